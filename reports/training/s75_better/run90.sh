#!/usr/bin/env bash
# Rule 90 (rule90.txt): X90 through the gate, C''' (against the shipped model, seeds 9 10), A (seeds 164 165), B', C+
# and T, each only after the one before passed. Re-running skips every draw on disk.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s75_better; S=/work/scratch/s39; REF=/work/scratch/s74/ref; OUT=$R/rule90_stages.txt
X=/work/scratch/s75; M=$X/models/X90_model; G=reports/training/s37_env_guidance/guard.py
if [ ! -f $M/model.safetensors ]; then  # rebuild X90 (rule90.txt)
  simdiff train deepen --model simdiff/assets/default_model --out $X/P63 --seed 63 >&2 &&
  simdiff train extrapolate --model /work/scratch/s74/models/X88_model --parent $X/P63 --lam 0.125 --out $M >&2 &&
  cp /work/scratch/s74/models/X88_model/sampling.json $M/ || exit 1
fi
sha256sum $M/model.safetensors | grep -q ^856504f9169ba456 || { echo "X90's weights are not rule 90's" >&2; exit 1; }
run() { RULE=90 N=X90 M=$M AS=164 STAGES="$1" STAGES_OUT=$OUT bash reports/training/s74_sim_reference/run87.sh; }
run gate; grep -q "rule 90: gate failed" $OUT && exit 0
echo "[$(date -u +%H:%M)] Cppp" >&2
for m in J40m X90; do
  d=$S/eval11/Cppp9_$m/-1.6,0,0; [ -f $d/check.json ] && continue
  if [ $m = J40m ]; then
    SIMDIFF_SCRATCH=$REF SEEDS="9 10" STEPS=50 W=2.5 ALPHA=0.5 ANCHOR=adapters \
      /usr/bin/time -f "stage Cppp9_J40m %e s" python $G -1.6,0,0 4 $d simdiff/assets/default_model >&2 || exit 1
  else
    SIMDIFF_SCRATCH=$REF SEEDS="9 10" STEPS=50 W=2.5 ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 EDIT_T=900 ETA=1 \
      /usr/bin/time -f "stage Cppp9_X90 %e s" python $G -1.6,0,0 1 $d $M >&2 || exit 1
  fi
done
python $R/v89.py $S/eval11/Cppp9_X90/-1.6,0,0 $S/eval11/Cppp9_J40m/-1.6,0,0 | tee -a $OUT | grep -q PASS \
  || { echo "rule 90: Cppp failed" | tee -a $OUT; exit 0; }
run "A B Cplus T"
