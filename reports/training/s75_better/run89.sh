#!/usr/bin/env bash
# Rule 89 (rule89.txt): C''' (X88 and the shipped model under g -1.6 against the simulator's val replays, seeds 7 8),
# then rule 87's B', C+ and T through run87.sh (RULE=89). Re-running skips every draw on disk.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s75_better; S=/work/scratch/s39; REF=/work/scratch/s74/ref; OUT=$R/rule89_stages.txt
M=/work/scratch/s74/models/X88_model; G=reports/training/s37_env_guidance/guard.py
echo "[$(date -u +%H:%M)] Cppp" >&2
d=$S/eval11/Cppp_J40m/-1.6,0,0
[ -f $d/check.json ] || SIMDIFF_SCRATCH=$REF SEEDS="7 8" STEPS=50 W=2.5 ALPHA=0.5 ANCHOR=adapters \
  /usr/bin/time -f "stage Cppp_J40m %e s" python $G -1.6,0,0 4 $d simdiff/assets/default_model >&2 || exit 1
d=$S/eval11/Cppp_X88/-1.6,0,0
[ -f $d/check.json ] || SIMDIFF_SCRATCH=$REF SEEDS="7 8" STEPS=50 W=2.5 ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 \
  EDIT_T=900 ETA=1 /usr/bin/time -f "stage Cppp_X88 %e s" python $G -1.6,0,0 1 $d $M >&2 || exit 1
python $R/v89.py $S/eval11/Cppp_X88/-1.6,0,0 $S/eval11/Cppp_J40m/-1.6,0,0 | tee -a $OUT | grep -q PASS \
  || { echo "rule 89: Cppp failed" | tee -a $OUT; exit 0; }
RULE=89 N=X88 M=$M STAGES="B Cplus T" STAGES_OUT=$OUT bash reports/training/s74_sim_reference/run87.sh
