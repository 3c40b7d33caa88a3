#!/usr/bin/env bash
# Backbone-only GPU run (issue 14): unpack a corpus pack and train the backbone on it until a wall-clock cap,
# then copy the exported model and the training log to $OUT. Fits one device command (<= 10 min).
#
# Carried (prepare on CPU, see docs/training_pipeline.md "GPU packaging"):
#   $PACK        corpus pack, e.g. `simdiff train pack CORPUS --out .gpu/corpus --splits train`
#   $TEXT_TABLE  its caption embeddings (`simdiff train text-table CORPUS --out FILE`); the device has no MiniLM
# Device command (repository root; device timeout_s 570):
#   OUT=$OUT PACK=.gpu/corpus TEXT_TABLE=.gpu/captions.safetensors bash scripts/gpu_backbone.sh
# Overrides: CONFIG (configs/backbone_small_gpu.json) SPLIT (train) MINUTES (7) LOADER_WORKERS (12) DEVICE (cuda)
#   DEADLINE_S (480: seconds from the start by which training must have stopped, a retry included) PYTHON (python)
#   INIT (a model folder to warm-start from: `train backbone --init`) SEED (the config's)
set -uo pipefail
: "${OUT:?set OUT to the output folder}"
: "${PACK:?set PACK to a corpus pack folder}"
: "${TEXT_TABLE:?set TEXT_TABLE to the caption table}"
CONFIG="${CONFIG:-configs/backbone_small_gpu.json}"
SPLIT="${SPLIT:-train}"
MINUTES="${MINUTES:-7}"
LOADER_WORKERS="${LOADER_WORKERS:-12}"
DEVICE="${DEVICE:-cuda}"
DEADLINE_S="${DEADLINE_S:-480}"
PY="${PYTHON:-python}"
WORK="${WORK:-${TMPDIR:-/tmp}/simdiff_gpu_backbone}"
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
start=$(date +%s)
mkdir -p "$OUT" "$WORK"
log() { echo "[$(( $(date +%s) - start ))s] $*" | tee -a "$OUT/run.log"; }
log "unpack $PACK"
"$PY" -m simdiff train unpack "$PACK" --out "$WORK/corpus" --workers 0 --no-progress 2>&1 | tee -a "$OUT/run.log"
# progress: the latest logged step every 30 s (the training itself runs without a progress bar)
( while sleep 30; do log "$(tail -n 1 "$WORK/run/train_log.jsonl" 2>/dev/null)"; done ) &
watcher=$!
train() {  # $1 minutes, $2 loader workers
  log "train backbone: --max-minutes $1 --loader-workers $2"
  "$PY" -m simdiff train backbone --data "$WORK/corpus" --split "$SPLIT" --out "$WORK/run" --config "$CONFIG" \
    --device "$DEVICE" --text-table "$TEXT_TABLE" --max-minutes "$1" --loader-workers "$2" --no-progress \
    ${INIT:+--init "$INIT"} ${SEED:+--seed "$SEED"} \
    2>&1 | tee -a "$OUT/run.log"
  return "${PIPESTATUS[0]}"
}
train "$MINUTES" "$LOADER_WORKERS"
status=$?
if [ "$status" != "0" ]; then  # e.g. the loader workers failed there: resume in-process with the time left
  left=$("$PY" -c "print(round(max(0.5, ($DEADLINE_S - ($(date +%s) - $start)) / 60), 2))")
  log "training failed ($status); resuming in-process for $left min"
  train "$left" 0
  status=$?
fi
kill "$watcher" 2>/dev/null
for f in "$WORK/run/model/"* "$WORK/run/train_log.jsonl" "$WORK/run/train_config.json"; do
  if [ -f "$f" ]; then cp "$f" "$OUT/"; fi
done
log "done status=$status"
exit "$status"
