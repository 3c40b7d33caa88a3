#!/usr/bin/env bash
# Deepen the shipped model and continue it on one GPU in one device command (issue 14, session 63): insert an
# identity layer after each backbone layer (`simdiff train deepen`: the same x̂₀ at step 0), train the deeper backbone
# on a corpus pack (`train backbone --init`), then fine-tune the moved adapters on it from augmented packs
# (`train adapters --adapters-init`). The two model folders come back as tars cut into <= 15 MiB parts
# (`cat NAME.tar.part_* | tar -x`), the logs as one small tar.
#
# Carried (prepare on CPU, docs/training_pipeline.md "GPU packaging"):
#   $PACK        corpus pack holding split $BB_SPLIT      $AUG_PACK  augmented pack(s), space-separated
#   $TEXT_TABLE  caption embeddings of both               $INIT      the SimDiff model folder to deepen
# Device command (repository root; device timeout_s 580):
#   OUT=$OUT PACK=.gpu/corpus AUG_PACK=".gpu/aug_weakg .gpu/aug_gen .gpu/aug_wind" TEXT_TABLE=.gpu/captions.safetensors \
#     INIT=simdiff/assets/default_model bash scripts/gpu_deepen.sh
# Overrides: BB_MINUTES (5.2) AD_MINUTES (2.4) BB_SPLIT (train_jumpx) BB_CONFIG (configs/backbone_deep_gpu.json)
#   AD_CONFIG (configs/adapters_paired_gpu_finetune.json) ENV_PAIRS (10) DRIFT (20) SEED (63) DEVICE (cuda)
#   WORKERS (cores - 2) PYTHON (python) EXTRA_BB / EXTRA_AD (more flags, e.g. "--steps 2" for a CPU rehearsal)
#   DEEPEN (1; 0: train INIT's own layers, no deepening, e.g. session 63's G63 carried as float16 by
#   `simdiff train precision`)
#   DEADLINE_S (555): seconds from the start by which the adapters must have stopped (their minutes are cut to fit;
#   the backbone's tar is written as soon as it is trained, so a late stop loses the adapters only)
# Every pack's split files are joined into one split `adapt` (packs made with --splits SPLIT hold only SPLIT).
set -uo pipefail
: "${OUT:?set OUT to the output folder}"
: "${PACK:?set PACK to a corpus pack folder}"
: "${AUG_PACK:?set AUG_PACK to augmented pack folder(s)}"
: "${TEXT_TABLE:?set TEXT_TABLE to the caption table}"
: "${INIT:?set INIT to the SimDiff model folder to deepen}"
PY="${PYTHON:-python}"
DEVICE="${DEVICE:-cuda}"
SEED="${SEED:-63}"
WORK="${WORK:-${TMPDIR:-/tmp}/simdiff_gpu_deepen}"
ncores=$(getconf _NPROCESSORS_ONLN)
WORKERS="${WORKERS:-$(( ncores > 2 ? ncores - 2 : 1 ))}"
BB_MINUTES="${BB_MINUTES:-5.2}"
AD_MINUTES="${AD_MINUTES:-2.4}"
DEADLINE_S="${DEADLINE_S:-555}"
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1 TORCH_ALLOW_TF32_CUBLAS_OVERRIDE=1
start=$(date +%s)
rm -rf "$WORK"
mkdir -p "$OUT" "$WORK/logs" "$WORK/data"
log() { echo "[$(( $(date +%s) - start ))s] $*" | tee -a "$WORK/logs/run.log"; }
cap() { "$PY" -c "print(int(($1 + 1.5) * 60))"; }  # a stage's hard stop: its minutes + 1.5 (then the next checkpoint is lost, not the run)

log "unpack $PACK and $AUG_PACK; deepen $INIT"
pids=()
"$PY" -m simdiff train unpack "$PACK" --out "$WORK/corpus" --workers 0 --no-progress > "$WORK/logs/unpack_corpus.log" 2>&1 &
pids+=($!)
data=()
for pk in $AUG_PACK; do
  d="$WORK/data/$(basename "$pk")"
  data+=("$d")
  "$PY" -m simdiff train unpack "$pk" --out "$d" --workers 0 --no-progress > "$WORK/logs/unpack_$(basename "$pk").log" 2>&1 &
  pids+=($!)
done
if [ "${DEEPEN:-1}" = "1" ]; then
  "$PY" -m simdiff train deepen --model "$INIT" --out "$WORK/deep" --seed "$SEED" 2>&1 | tee -a "$WORK/logs/run.log"
  ok=${PIPESTATUS[0]}
else  # continue INIT as it is (e.g. an already deepened model carried as float16: `simdiff train precision`)
  ln -s "$(cd "$INIT" && pwd)" "$WORK/deep" && ok=0 || ok=1
  log "DEEPEN=0: $INIT continued without new layers"
fi
for p in "${pids[@]}"; do wait "$p" || ok=1; done
cat "$WORK"/logs/unpack_*.log | tee -a "$WORK/logs/run.log"
for d in "${data[@]}"; do cat "$d"/*.txt > "$d/adapt.txt" 2>/dev/null; done
if [ "$ok" != "0" ]; then log "unpack or deepen failed"; fi

( while sleep 30; do log "$(tail -qn 1 "$WORK"/bb/train_log.jsonl "$WORK"/ad/train_log.jsonl 2>/dev/null | tr '\n' ' ')"; done ) &
watcher=$!
bb=1
if [ "$ok" = "0" ]; then
  log "backbone: ${BB_SPLIT:-train_jumpx}, --init deep, $BB_MINUTES min, $WORKERS loader workers"
  # shellcheck disable=SC2086
  timeout --signal=INT "$(cap "$BB_MINUTES")" "$PY" -m simdiff train backbone --data "$WORK/corpus" \
    --split "${BB_SPLIT:-train_jumpx}" --init "$WORK/deep" --out "$WORK/bb" --config "${BB_CONFIG:-configs/backbone_deep_gpu.json}" \
    --seed "$SEED" --device "$DEVICE" --text-table "$TEXT_TABLE" --max-minutes "$BB_MINUTES" \
    --loader-workers "$WORKERS" --no-progress ${EXTRA_BB:-} > "$WORK/logs/backbone.log" 2>&1
  bb=$?
  tail -n 3 "$WORK/logs/backbone.log" | tee -a "$WORK/logs/run.log"
fi
if [ -d "$WORK/bb/model" ]; then tar -C "$WORK/bb" -cf - model | split -b 15m - "$OUT/bb.tar.part_"; fi
cp "$WORK"/bb/train_log.jsonl "$WORK/logs/bb_train_log.jsonl" 2>/dev/null
tar -C "$WORK" -cf "$OUT/logs.tar" logs  # rewritten at the end; here in case the adapters overrun the device's limit
ad=1
if [ "$bb" = "0" ] && [ -f "$WORK/bb/model/model.safetensors" ]; then
  left=$(( DEADLINE_S - ($(date +%s) - start) ))
  minutes=$("$PY" -c "print(round(max(0.2, min($AD_MINUTES, ($left - 50) / 60)), 2))")
  log "adapters: --adapters-init deep, λ ${ENV_PAIRS:-10}, μ ${DRIFT:-20}, $minutes min (hard stop in $left s)"
  # shellcheck disable=SC2086
  timeout --signal=INT "$(( left > 30 ? left : 30 ))" "$PY" -m simdiff train adapters --data "${data[@]}" --split adapt \
    --init "$WORK/bb/model" --adapters-init "$WORK/deep" --out "$WORK/ad" \
    --config "${AD_CONFIG:-configs/adapters_paired_gpu_finetune.json}" --env-pairs "${ENV_PAIRS:-10}" \
    --env-pairs-drift "${DRIFT:-20}" --seed "$SEED" --device "$DEVICE" --text-table "$TEXT_TABLE" \
    --max-minutes "$minutes" --loader-workers "$WORKERS" --no-progress ${EXTRA_AD:-} > "$WORK/logs/adapters.log" 2>&1
  ad=$?
  tail -n 3 "$WORK/logs/adapters.log" | tee -a "$WORK/logs/run.log"
fi
kill "$watcher" 2>/dev/null
if [ -d "$WORK/ad/model" ]; then tar -C "$WORK/ad" -cf - model | split -b 15m - "$OUT/ad.tar.part_"; fi
for run in bb ad; do
  for f in train_log.jsonl train_config.json; do [ -f "$WORK/$run/$f" ] && cp "$WORK/$run/$f" "$WORK/logs/${run}_$f"; done
done
[ -f "$WORK/deep/deepening.json" ] && cp "$WORK/deep/deepening.json" "$WORK/logs/"
log "done backbone=$bb adapters=$ad"
tar -C "$WORK" -cf "$OUT/logs.tar" logs
exit "$ad"
