#!/usr/bin/env bash
# Continue a shipped model on one GPU in one device command (issue 14): warm-start the backbone from INIT's
# backbone on a corpus pack (scripts/gpu_backbone.sh, `train backbone --init`), then train the adapters on the new
# backbone from an augmented pack, starting from INIT's own Sim Encoder and adapters (scripts/gpu_adapters.sh,
# `train adapters --adapters-init`). Two tars come back: $OUT/backbone.tar (model + logs) and $OUT/<RUN>.tar.
#
# Carried (prepare on CPU, docs/training_pipeline.md "GPU packaging"):
#   $PACK        corpus pack of the train split      $AUG_PACK  augmented pack(s), space-separated
#   $TEXT_TABLE  caption embeddings of both          $INIT      the SimDiff model folder to continue
# Device command (repository root; device timeout_s 580):
#   OUT=$OUT PACK=.gpu/corpus AUG_PACK=".gpu/aug_weakg .gpu/aug_gen" TEXT_TABLE=.gpu/captions.safetensors \
#     INIT=simdiff/assets/default_model bash scripts/gpu_continue.sh
# Overrides: BB_MINUTES (4.0) AD_MINUTES (2.6) RUN (pair10:10, NAME:λ of --env-pairs) AD_SPLIT (first_try)
#   BB_CONFIG AD_CONFIG (the two scripts' defaults) SEED (11) DEVICE (cuda) PYTHON (python)
#   BB_WORKERS AD_WORKERS (loader workers: 14, every core)
set -uo pipefail
: "${OUT:?set OUT to the output folder}"
: "${PACK:?set PACK to a corpus pack folder}"
: "${AUG_PACK:?set AUG_PACK to augmented pack folder(s)}"
: "${TEXT_TABLE:?set TEXT_TABLE to the caption table}"
: "${INIT:?set INIT to the SimDiff model folder to continue}"
WORK="${WORK:-${TMPDIR:-/tmp}/simdiff_gpu_continue}"
RUN="${RUN:-pair10:10}"
SEED="${SEED:-11}"
ncores=$(getconf _NPROCESSORS_ONLN)
start=$(date +%s)
mkdir -p "$OUT" "$WORK"
log() { echo "[$(( $(date +%s) - start ))s] $*" | tee -a "$OUT/continue.log"; }

log "backbone: warm start from $INIT for ${BB_MINUTES:-4.0} min"
# shellcheck disable=SC2086
env OUT="$WORK/backbone" WORK="$WORK/bb" INIT="$INIT" SEED="$SEED" MINUTES="${BB_MINUTES:-4.0}" \
  LOADER_WORKERS="${BB_WORKERS:-$(( ncores > 2 ? ncores - 2 : 1 ))}" DEADLINE_S="${BB_DEADLINE_S:-300}" \
  ${BB_CONFIG:+CONFIG=$BB_CONFIG} bash scripts/gpu_backbone.sh > "$WORK/backbone.out" 2>&1
bb=$?
tail -n 4 "$WORK/backbone.out" | tee -a "$OUT/continue.log"
tar -C "$WORK" -cf "$OUT/backbone.tar" backbone 2>>"$OUT/continue.log" || log "backbone: nothing to tar"
if [ "$bb" != "0" ] || [ ! -f "$WORK/backbone/model.safetensors" ]; then
  log "backbone failed ($bb): adapters not trained"
  exit 1
fi

log "adapters $RUN on the new backbone, warm start from $INIT's adapters, ${AD_MINUTES:-2.6} min"
# shellcheck disable=SC2086
env OUT="$WORK/adapters" WORK="$WORK/ad" BACKBONE="$WORK/backbone" ADAPTERS_INIT="$INIT" SEED="$SEED" RUNS="$RUN" \
  SPLIT="${AD_SPLIT:-first_try}" MINUTES="${AD_MINUTES:-2.6}" LOADER_WORKERS="${AD_WORKERS:-$ncores}" \
  ${AD_CONFIG:+CONFIG=$AD_CONFIG} bash scripts/gpu_adapters.sh > "$WORK/adapters.out" 2>&1
ad=$?
tail -n 4 "$WORK/adapters.out" | tee -a "$OUT/continue.log"
name=${RUN%%:*}
if [ -f "$WORK/adapters/$name.tar" ]; then
  tar -C "$WORK/adapters" -rf "$WORK/adapters/$name.tar" run.log 2>/dev/null
  mv "$WORK/adapters/$name.tar" "$OUT/"
fi
log "done backbone=$bb adapters=$ad"
exit "$ad"
