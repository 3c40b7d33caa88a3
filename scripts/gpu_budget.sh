#!/usr/bin/env bash
# The GPU budget run (issue 14): one H200-class GPU, <= 25 min wall, <= 64 MiB carried, results <= 16 MiB per file.
#
# Carried in the repository copy (prepare on CPU, see docs/training_pipeline.md):
#   $PACK      a corpus pack          (simdiff train pack CORPUS --out $PACK)
#   $AUG_PACK  optional augmented pack (else the simulation runs here on $SIM_WORKERS cores)
# Device command (from the repository root):
#   OUT=$OUT PACK=packs/corpus AUG_PACK=packs/augmented bash scripts/gpu_budget.sh
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
# shellcheck disable=SC2206
if [ -n "${EXTRA:-}" ]; then args+=($EXTRA); fi
start=$(date +%s)
"$PY" -m simdiff "${args[@]}" 2>&1 | tee "$OUT/pipeline.log"
echo "wall_s=$(( $(date +%s) - start ))" | tee -a "$OUT/pipeline.log"
# Only small files travel back: the sharded model, the stage markers and the evaluation.
mkdir -p "$OUT/result"
cp -r "$RUN/export/sharded" "$OUT/result/model"
cp "$RUN/export/training.json" "$RUN/pipeline_config.json" "$OUT/result/"
cp -r "$RUN/stages" "$OUT/result/stages"
if [ -f "$RUN/evaluation/evaluation.json" ]; then cp "$RUN/evaluation/evaluation.json" "$OUT/result/"; fi
"$PY" - "$OUT/result" <<'PYCHECK'
import sys
from pathlib import Path
limit = 16 * 2**20
big = [p for p in Path(sys.argv[1]).rglob("*") if p.is_file() and p.stat().st_size > limit]
if big:
    sys.exit(f"files over 16 MiB in the result: {big}")
print(f"result files all <= 16 MiB: {sum(1 for p in Path(sys.argv[1]).rglob('*') if p.is_file())} files")
PYCHECK

