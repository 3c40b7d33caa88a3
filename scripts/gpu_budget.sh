#!/usr/bin/env bash
# The GPU budget run (issue 14): one H200-class GPU, <= 64 MiB carried, results <= 16 MiB per file, and the whole
# pipeline inside one device command (at most 10 min; a session gets 15 min of device time, machine start included).
#
# Carried in the repository copy (prepare on CPU, see docs/training_pipeline.md):
#   $PACK        a corpus pack          (simdiff train pack CORPUS --out $PACK)
#   $AUG_PACK    optional augmented pack (else the simulation runs here on $SIM_WORKERS cores)
#   $TEXT_TABLE  the corpus's caption embeddings (simdiff train text-table CORPUS --out FILE): the device has no
#                MiniLM weights (88 MB, more than can be carried), so without a table the text stages fail there
# Device command (from the repository root; give the device call a timeout of 600 s):
#   OUT=$OUT PACK=packs/corpus AUG_PACK=packs/augmented TEXT_TABLE=packs/captions.safetensors bash scripts/gpu_budget.sh
# MINUTES (default 7 for BUDGET=gpu, else the preset's own caps): wall-clock share of the training stages
#   (backbone 60 %, adapters 15 %; each stops at its next checkpoint past its share) and, below 20 minutes, a small
#   evaluator and evaluation, so the pipeline ends, exports and copies its result inside the device's command limit.
#   The pipeline itself is stopped at MINUTES + 2 whatever happens, and whatever finished is copied back.
# Overrides for a CPU rehearsal (tests/test_train_pack.py runs exactly this with BUDGET=quick DEVICE=cpu):
#   BUDGET (gpu) DEVICE (cuda) SIM_WORKERS (16) EXTRA ("--set backbone.steps=2 ...") PIP (1: install --no-deps)
set -euo pipefail
: "${OUT:?set OUT to the output folder}"
: "${PACK:?set PACK to a corpus pack folder}"
BUDGET="${BUDGET:-gpu}"
DEVICE="${DEVICE:-cuda}"
SIM_WORKERS="${SIM_WORKERS:-16}"
RUN="${RUN:-${TMPDIR:-/tmp}/simdiff_gpu_run}"  # outside $OUT: only result/ and the log travel back
PY="${PYTHON:-python}"
if [ "${PIP:-1}" = "1" ]; then
  "$PY" -m pip install --no-deps --no-build-isolation -q -e . >/dev/null
fi
args=(train pipeline --budget "$BUDGET" --out "$RUN" --corpus "$PACK" --device "$DEVICE" --sim-workers "$SIM_WORKERS"
      --set export.shard_mib=16 --no-progress)
if [ -n "${AUG_PACK:-}" ]; then args+=(--augmented "$AUG_PACK"); fi
if [ -n "${TEXT_TABLE:-}" ]; then args+=(--text-table "$TEXT_TABLE"); fi
if [ "$BUDGET" = "gpu" ]; then MINUTES="${MINUTES:-7}"; else MINUTES="${MINUTES:-0}"; fi
if [ "$MINUTES" != "0" ]; then
  share() { "$PY" -c "print(round($MINUTES * $1, 2))"; }
  args+=(--set "backbone.max_minutes=$(share 0.6)" --set "adapters.max_minutes=$(share 0.15)")
  if [ "$("$PY" -c "print(int($MINUTES < 20))")" = "1" ]; then
    args+=(--set evaluator.epochs=2 --set evaluation.replications=1 --set evaluation.samples_limit=64
           --set evaluation.steps=20)
  fi
fi
# shellcheck disable=SC2206
if [ -n "${EXTRA:-}" ]; then args+=($EXTRA); fi
start=$(date +%s)
limit=()
if [ "$MINUTES" != "0" ]; then limit=(timeout --signal=INT "$("$PY" -c "print(int(($MINUTES + 2) * 60))")"); fi
set +e
"${limit[@]}" "$PY" -m simdiff "${args[@]}" 2>&1 | tee "$OUT/pipeline.log"
status=${PIPESTATUS[0]}
set -e
echo "wall_s=$(( $(date +%s) - start )) status=$status" | tee -a "$OUT/pipeline.log"
# Only small files travel back: the sharded model, the stage markers and the evaluation (whatever finished).
mkdir -p "$OUT/result"
if [ -d "$RUN/export/sharded" ]; then cp -r "$RUN/export/sharded" "$OUT/result/model"; fi
for f in "$RUN/export/training.json" "$RUN/pipeline_config.json" "$RUN/evaluation/evaluation.json"; do
  if [ -f "$f" ]; then cp "$f" "$OUT/result/"; fi
done
if [ -d "$RUN/stages" ]; then cp -r "$RUN/stages" "$OUT/result/stages"; fi
"$PY" - "$OUT/result" <<'PYCHECK'
import sys
from pathlib import Path
limit = 16 * 2**20
big = [p for p in Path(sys.argv[1]).rglob("*") if p.is_file() and p.stat().st_size > limit]
if big:
    sys.exit(f"files over 16 MiB in the result: {big}")
print(f"result files all <= 16 MiB: {sum(1 for p in Path(sys.argv[1]).rglob('*') if p.is_file())} files")
PYCHECK
exit "$status"
