# Rule 71's stage C' (val captions under g -1.6, n 128 x seeds 1 2 3 4, s_e 4; verdict c71.py): bash cprime4.sh NAME MODEL.
# Draws NAME's seeds 1 2 and 3 4 and the shipped model's seeds 3 4 (its seeds 1 2: session 54's C12_J40m_se4) unless
# already drawn; exit 0 on a pass.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; NAME=$1; M=$2; SE=${SE:-4}  # the candidate's s_e (the shipped reference: 4)
export SIMDIFF_SCRATCH=$S STEPS=50
draw() {  # $1 folder prefix, $2 seeds, $3 model, $4 s_e
  [ -f $S/eval11/$1/-1.6,0,0/check.json ] && return 0
  SEEDS="$2" /usr/bin/time -f "stage$1 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 $4 \
    $S/eval11/$1/-1.6,0,0 $3 >&2
}
draw C12_${NAME}_se$SE "1 2" $M $SE || exit 1
draw C34_${NAME}_se$SE "3 4" $M $SE || exit 1
draw C34_J40m_se4 "3 4" simdiff/assets/default_model 4 || exit 1
python reports/training/s63_deepen/c71.py ${NAME}_se$SE
