#!/usr/bin/env bash
# Rule 95 (rule95.txt): X95 = one of train94's exports at steps 800 / 1000 / 1200 (X93's adapters put back), chosen by
# S' (select95.py, val seeds 704-707), then A, B, T and C+ with run87.sh's stages; verdict lines in rule95_stages.txt.
# Re-running skips every draw on disk. Needs /work/scratch/s78/fine800 (or models/X94_800), fine1000 (keep1000.sh) and
# train94 finished (its model/ is the step-1200 export).
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s78_captioned; W=/work/scratch/s78; RUN=/work/scratch/s77/train94
X93=${X93:-reports/training/s76_lambda/X93_model}; OUT=$R/rule95_stages.txt
stamp() { echo "[$(date -u +%H:%M)] $*" >&2; }
K=$R/X95_model  # the committed copy of the chosen weights (scripts/restore_report_weights.sh brings them back)
if grep -q "^X95 = X94_800 (5801f52673e8d161)" $OUT 2>/dev/null; then  # S' ran (session 78): straight to the stages
  M=$W/models/X94_800
  if [ ! -f $M/model.safetensors ]; then
    [ -f $K/model.safetensors ] || bash scripts/restore_report_weights.sh > /dev/null
    mkdir -p $M && cp $K/* $M/
  fi
  sha256sum $M/model.safetensors | grep -q ^5801f52673e8d161 || { echo "X95's weights do not hash to 5801f526..." >&2; exit 1; }
  RULE=95 N=X95 M=$M AS=170 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="8 9" B_VERDICT="python $R/v94.py earth" \
    T_VERDICT="python $R/v94.py test" STAGES="${STAGES:-A B T Cplus}" STAGES_OUT=$OUT \
    bash reports/training/s74_sim_reference/run87.sh
  exit 0
fi
until [ -f $W/fine1000/model.safetensors ]; do sleep 20; done
until [ "$(cat $RUN/checkpoints/latest 2>/dev/null)" = "step_000001200" ] && ! pgrep -f "train backbone --data /work/scratch/s77/c3loop" > /dev/null; do sleep 20; done
[ -f $W/fine1200/model.safetensors ] || { mkdir -p $W/fine1200.tmp && cp $RUN/model/* $W/fine1200.tmp/ && mv $W/fine1200.tmp $W/fine1200; }
for s in 800 1000 1200; do
  X=$W/models/X94_$s
  [ -f $X/model.safetensors ] || simdiff train extrapolate --model $X93 --parent $W/fine$s --lam -1 --out $X
  sha256sum $X/model.safetensors | tee -a $W/X95_sha.txt
  for seed in 704 705 706 707; do
    for p in "a person walks forward" "a person is walking straight ahead" "a person runs forward" \
             "a person jogs forward" "a person jumps forward"; do
      [ "$p" = "a person jumps forward" ] && [ $seed != 704 ] && continue
      o="$W/select95/$s/$seed/${p// /_}"
      [ -f "$o/generation.json" ] || simdiff generate "$p" --model $X --frames 120 --num-samples 8 --seed $seed \
        --format npy --no-video -q --out "$o" > /dev/null
    done
  done
  stamp "S' samples of step $s"
done
{ echo "S' (val seeds 704-707, n 32 per walk / run prompt):"; (cd $R && python select95.py \
  /work/main/reports/training/s76_lambda/test/X93/check.json $W/select95/800 $W/select95/1000 $W/select95/1200); } \
  | tee -a $OUT > $W/select95.txt
grep -q "^X95 = " $W/select95.txt || { echo "rule 95: S' failed" | tee -a $OUT; exit 0; }
STEP=$(sed -n 's#^X95 = .*/##p' $W/select95.txt); M=$W/models/X94_$STEP
echo "X95 = X94_$STEP ($(sha256sum $M/model.safetensors | cut -c1-16))" | tee -a $OUT
RULE=95 N=X95 M=$M AS=170 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="8 9" B_VERDICT="python $R/v94.py earth" \
  T_VERDICT="python $R/v94.py test" STAGES="${STAGES:-A B T Cplus}" STAGES_OUT=$OUT \
  bash reports/training/s74_sim_reference/run87.sh
