# D4: X15sa's Earth and wind, the gravity answer of J40m_sa (another backbone, transplanted at the same x_t), from
# X15sa, 300 steps, λ 10, μ 20, α 0.5 / 1, EMA 0.99; then the probe with the low-gravity screen. GAIN=k NAME=... for k.
# D5: NAME=D5 INIT=/work/scratch/s61/D4_model FT=/work/scratch/s59/X15sg_model (X15sg's answer where the Earth motion flies);
# D6: the same with NAME=D6 MINF=0.2 (flights of >= 0.2 s only).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s61; NAME=${NAME:-D4}; GAIN=${GAIN:-1.0}; STEPS=${STEPS:-300}
GT=${GT:-/work/scratch/s55/J40m_sa_model}; INIT=${INIT:-/work/scratch/s57/X15sa_model}
FLIGHT="${FT:+--flight-teacher $FT} ${MINF:+--min-flight-s $MINF}"
mkdir -p $O
/usr/bin/time -f "distill $NAME %e s" python reports/training/s61_distill/distill.py --student-init $INIT $FLIGHT \
  --gravity-teacher $GT --wind-teacher /work/scratch/s57/X15sa_model --earth-teacher /work/scratch/s57/X15sa_model \
  --backbone /work/scratch/s57/wx1.5 --out $O/ad$NAME --data $S/aug_weakg $S/aug_gen $S/aug_wind \
  --steps $STEPS --gravity-gain $GAIN --pairs 10 --drift 20 --alphas 0.5 1.0 --seed 61 --text-table .gpu/captions.safetensors || exit 1
M=$O/${NAME}_model; rm -rf $M; cp -r $O/ad$NAME/model $M; cp /work/scratch/s57/X15sa_model/sampling.json $M/
python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 $M
