#!/usr/bin/env bash
# Rule 90 (rule90.txt): X90 through the gate, C''' (against the shipped model, seeds 9 10), A (seeds 164 165), B', C+
# and T, each only after the one before passed. Re-running skips every draw on disk.
# Rule 91 (run91.sh) runs the same with RULE=91 CSEEDS="11 12" MARGIN=0.03 GATE=carried (rule 90's gate passed).
set -u
RULE=${RULE:-90} CSEEDS=${CSEEDS:-9 10} MARGIN=${MARGIN:-0} GATE=${GATE:-run}
cd /work/main; . .venv/bin/activate
R=reports/training/s75_better; S=/work/scratch/s39; REF=/work/scratch/s74/ref; OUT=$R/rule${RULE}_stages.txt
X=/work/scratch/s75; M=$X/models/X90_model; G=reports/training/s37_env_guidance/guard.py
if [ ! -f $M/model.safetensors ]; then  # rebuild X90 (rule90.txt)
  simdiff train deepen --model simdiff/assets/default_model --out $X/P63 --seed 63 >&2 &&
  simdiff train extrapolate --model /work/scratch/s74/models/X88_model --parent $X/P63 --lam 0.125 --out $M >&2 &&
  cp /work/scratch/s74/models/X88_model/sampling.json $M/ || exit 1
fi
sha256sum $M/model.safetensors | grep -q ^856504f9169ba456 || { echo "X90's weights are not rule 90's" >&2; exit 1; }
run() { RULE=$RULE N=X90 M=$M AS=164 STAGES="$1" STAGES_OUT=$OUT bash reports/training/s74_sim_reference/run87.sh; }
[ $GATE = run ] && { run gate; grep -q "rule $RULE: gate failed" $OUT && exit 0; }
echo "[$(date -u +%H:%M)] Cppp" >&2
for m in J40m X90; do
  d=$S/eval11/Cppp${CSEEDS%% *}_$m/-1.6,0,0; [ -f $d/check.json ] && continue
  if [ $m = J40m ]; then
    SIMDIFF_SCRATCH=$REF SEEDS="$CSEEDS" STEPS=50 W=2.5 ALPHA=0.5 ANCHOR=adapters \
      /usr/bin/time -f "stage Cppp_J40m %e s" python $G -1.6,0,0 4 $d simdiff/assets/default_model >&2 || exit 1
  else
    SIMDIFF_SCRATCH=$REF SEEDS="$CSEEDS" STEPS=50 W=2.5 ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 EDIT_T=900 ETA=1 \
      /usr/bin/time -f "stage Cppp_X90 %e s" python $G -1.6,0,0 1 $d $M >&2 || exit 1
  fi
done
python $R/v89.py $S/eval11/Cppp${CSEEDS%% *}_X90/-1.6,0,0 $S/eval11/Cppp${CSEEDS%% *}_J40m/-1.6,0,0 --margin $MARGIN | tee -a $OUT | grep -q PASS \
  || { echo "rule $RULE: Cppp failed" | tee -a $OUT; exit 0; }
run "A B Cplus T"
