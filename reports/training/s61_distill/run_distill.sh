# Two-teacher distillation (gravity X15sg, wind X15sa), EMA 0.99; then the probe. D1: NAME=D1 (from the ½ soup, 400 steps,
# plain MSE); D2: NAME=D2 INIT=/work/scratch/s61/D1_model STEPS=300 PAIRS=10 DRIFT=20; D3: as D2 from D2_model with
# ALPHAS="0.5 1.0".
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s61; NAME=${NAME:-D1}; GAIN=${GAIN:-1.0}; STEPS=${STEPS:-400}
INIT=${INIT:-/work/scratch/s60/soup50}
mkdir -p $O
/usr/bin/time -f "distill $NAME %e s" python reports/training/s61_distill/distill.py --student-init $INIT \
  --gravity-teacher /work/scratch/s59/X15sg_model --wind-teacher /work/scratch/s57/X15sa_model \
  --backbone /work/scratch/s57/wx1.5 --out $O/ad$NAME --data $S/aug_weakg $S/aug_gen $S/aug_wind \
  --steps $STEPS --gravity-gain $GAIN --pairs ${PAIRS:-0} --drift ${DRIFT:-0} --alphas ${ALPHAS:-} --seed 61 --text-table .gpu/captions.safetensors || exit 1
M=$O/${NAME}_model; rm -rf $M; cp -r $O/ad$NAME/model $M; cp /work/scratch/s57/X15sa_model/sampling.json $M/
python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 $M
