#!/usr/bin/env bash
# Rule 94 (rule94.txt): build X94 from train94's export at STEP (default 400; the screen's fallbacks 600, 800), screen
# it (S), then A, B, T and C+ with run87.sh's stages; verdict lines in rule94_stages.txt. Re-running skips every draw
# on disk. Needs /work/scratch/s77/train94 (../s77_run_speed/train94.sh; this script stops it once STEP's export is
# written and keeps that export) and X93 (simdiff/assets/default_model until X94 ships).
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s78_captioned; STEP=${STEP:-400}; RUN=/work/scratch/s77/train94; W=/work/scratch/s78
F=$W/fine$STEP; X=$W/models/X94_$STEP; X93=${X93:-reports/training/s76_lambda/X93_model}
OUT=$R/rule94_stages.txt
stamp() { echo "[$(date -u +%H:%M)] $*" >&2; }
mkdir -p $W/models
if [ ! -f $F/model.safetensors ]; then
  want=$(printf 'step_%09d' $STEP)
  until [ "$(cat $RUN/checkpoints/latest 2>/dev/null)" = "$want" ]; do sleep 20; done
  sleep 60  # the export follows the checkpoint
  mkdir -p $F.tmp && cp $RUN/model/* $F.tmp/ && mv $F.tmp $F
  pkill -f "train backbone --data /work/scratch/s77/c3loop" || true
  stamp "kept the step-$STEP export, stopped the trainer"
fi
[ -f $X/model.safetensors ] || simdiff train extrapolate --model $X93 --parent $F --lam -1 --out $X
sha256sum $X/model.safetensors | tee -a $W/X94_sha.txt
stamp S
for p in "a person walks forward" "a person is walking straight ahead" "a person runs forward" "a person jogs forward" \
         "a person jumps forward"; do
  o="$W/screen/$STEP/${p// /_}"
  [ -f "$o/generation.json" ] || simdiff generate "$p" --model $X --frames 120 --num-samples 8 --seed 700 \
    --format npy --no-video -q --out "$o" > /dev/null
done
{ echo "S step $STEP (val seed 700, n 8 per prompt):"; (cd $R && python screen94.py $W/screen/$STEP \
  /work/main/reports/training/s76_lambda/test/X93/check.json); } | tee -a $OUT | grep -q "S PASS" \
  || { echo "rule 94: S failed at step $STEP" | tee -a $OUT; exit 0; }
RULE=94 N=X94 M=$X AS=168 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="6 7" B_VERDICT="python $R/v94.py earth" \
  T_VERDICT="python $R/v94.py test" STAGES="${STAGES:-A B T Cplus}" STAGES_OUT=$OUT \
  bash reports/training/s74_sim_reference/run87.sh
