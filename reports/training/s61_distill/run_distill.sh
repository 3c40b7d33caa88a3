# Distil the adapters on the wx1.5 backbone (distill.py, EMA 0.99, seed 61), then the probe. Settings by variable:
#   NAME  run name (model in /work/scratch/s61/NAME_model)     INIT  student start      STEPS  (400)
#   G     gravity teacher (X15sg)   E  Earth teacher (G's)     W     wind teacher (X15sa)
#   FT    flight teacher (none)     MINF  its min flight, s    PAIRS, DRIFT  λ, μ (0)   ALPHAS  ("": α 1)   GAIN  k (1)
#   MOON  walk/run samples per prompt for the probe's low-gravity screen (0: none)
# D1: NAME=D1 (the ½ soup, plain MSE; ran an earlier form of the loss, see README)
# D2: NAME=D2 INIT=/work/scratch/s61/D1_model STEPS=300 PAIRS=10 DRIFT=20
# D3: NAME=D3 INIT=/work/scratch/s61/D2_model STEPS=300 PAIRS=10 DRIFT=20 ALPHAS="0.5 1.0"
# D4-D6: run_d4.sh
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s61; NAME=${NAME:-D1}; STEPS=${STEPS:-400}
INIT=${INIT:-/work/scratch/s60/soup50}; G=${G:-/work/scratch/s59/X15sg_model}; W=${W:-/work/scratch/s57/X15sa_model}
OPT="${E:+--earth-teacher $E} ${FT:+--flight-teacher $FT} ${MINF:+--min-flight-s $MINF} ${ALPHAS:+--alphas $ALPHAS}"
mkdir -p $O
/usr/bin/time -f "distill $NAME %e s" python reports/training/s61_distill/distill.py --student-init $INIT \
  --gravity-teacher $G --wind-teacher $W $OPT --backbone /work/scratch/s57/wx1.5 --out $O/ad$NAME \
  --data $S/aug_weakg $S/aug_gen $S/aug_wind --steps $STEPS --gravity-gain ${GAIN:-1.0} --pairs ${PAIRS:-0} \
  --drift ${DRIFT:-0} --seed 61 --text-table .gpu/captions.safetensors || exit 1
M=$O/${NAME}_model; rm -rf $M; cp -r $O/ad$NAME/model $M; cp /work/scratch/s57/X15sa_model/sampling.json $M/
python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon ${MOON:-0} $M
