# Stage C' (val captions under g -1.6, n 128 x seeds 1 2, s_e 4; verdict c51.py C12, bars from the shipped model;
# exit 0 on a pass): bash cprime.sh NAME MODEL. Samples already generated for NAME are scored again, not redrawn.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; NAME=$1; M=$2
export SIMDIFF_SCRATCH=$S STEPS=50
if [ ! -f $S/eval11/C12_${NAME}_se4/-1.6,0,0/check.json ]; then
  SEEDS="1 2" /usr/bin/time -f "stageC12 $NAME %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
    $S/eval11/C12_${NAME}_se4/-1.6,0,0 $M >&2 || exit 1
fi
python reports/training/s56_source_anchored/c51.py C12 ${NAME}_se4
