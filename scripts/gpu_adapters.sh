#!/usr/bin/env bash
# Adapters-only GPU run (issue 14): unpack an augmented pack and train several SimDiff adapter variants side by
# side on one GPU (the small backbone leaves it mostly idle; the batch loaders share the cores) until a wall-clock
# cap, then tar each run's exported model and logs into $OUT (one file per run; a tar over PART_KIB, 15 MiB, is cut
# into NAME.tar.part_aa, _ab, … since the device returns files of <= 16 MiB, at most 8 of them).
#
# Carried (prepare on CPU):
#   $AUG_PACK    augmented pack(s), e.g. `simdiff train pack AUGMENTED --out .gpu/aug --splits all`; several
#                space-separated packs are trained on as one dataset
#   $TEXT_TABLE  caption embeddings (`simdiff train text-table CORPUS --out FILE`); the device has no MiniLM
#   $BACKBONE    the frozen backbone's model folder (model.safetensors + config.json); a SimDiff model folder
#                works too (only its backbone is loaded), e.g. simdiff/assets/default_model, which travels anyway
# Device command (repository root; device timeout_s 570):
#   OUT=$OUT AUG_PACK=.gpu/aug TEXT_TABLE=.gpu/captions.safetensors BACKBONE=.gpu/backbone \
#     RUNS="plain:0 pair10:10" bash scripts/gpu_adapters.sh
# RUNS: space-separated NAME:LAMBDA[:MU] (λ of --env-pairs, 0 = the paper's plain loss; MU of --env-pairs-drift,
#   the twins' mean root-velocity term, default 0).
# AUG_PACK_<NAME> (optional, per run): that run's packs instead of AUG_PACK, so runs side by side can differ in their
#   data mix; a pack listed k times is drawn k times as often (each pack is unpacked once).
# Overrides: CONFIG (configs/adapters_paired_gpu.json) SPLIT (all; `adapt`: each pack's split files joined, for
#   packs made with --splits NAME) MINUTES (7) LOADER_WORKERS (cores / runs)
#   DEVICE (cuda) PYTHON (python) ADAPTERS_INIT (a SimDiff folder to warm-start the adapters from) SEED
#   PART_KIB (15360: larger tars are cut into parts of this size, e.g. an 8-layer model's 27 MB)
set -uo pipefail
: "${OUT:?set OUT to the output folder}"
: "${AUG_PACK:?set AUG_PACK to an augmented pack folder}"
: "${TEXT_TABLE:?set TEXT_TABLE to the caption table}"
: "${BACKBONE:?set BACKBONE to the backbone model folder}"
: "${RUNS:?set RUNS, e.g. \"plain:0 pair10:10\"}"
CONFIG="${CONFIG:-configs/adapters_paired_gpu.json}"
SPLIT="${SPLIT:-all}"
MINUTES="${MINUTES:-7}"
DEVICE="${DEVICE:-cuda}"
PY="${PYTHON:-python}"
WORK="${WORK:-${TMPDIR:-/tmp}/simdiff_gpu_adapters}"
nruns=$(echo $RUNS | wc -w)
ncores=$(getconf _NPROCESSORS_ONLN)  # not nproc: it follows OMP_NUM_THREADS
LOADER_WORKERS="${LOADER_WORKERS:-$(( ncores / nruns > 0 ? ncores / nruns : 1 ))}"
export PYTHONPATH="$PWD${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
start=$(date +%s)
mkdir -p "$OUT" "$WORK"
log() { echo "[$(( $(date +%s) - start ))s] $*" | tee -a "$OUT/run.log"; }
declare -A unpacked=()  # pack path -> its unpacked folder
unpack() {  # $1 pack path; sets $d to its unpacked folder, unpacking it the first time
  d="$WORK/data/$(basename "$1")"
  if [ -n "${unpacked[$1]:-}" ]; then return 0; fi
  local other
  for other in "${!unpacked[@]}"; do
    [ "${unpacked[$other]}" = "$d" ] && { echo "gpu_adapters.sh: two packs named $(basename "$1"): $other and $1" >&2; exit 2; }
  done
  log "unpack $1"
  "$PY" -m simdiff train unpack "$1" --out "$d" --workers 0 --no-progress 2>&1 | tee -a "$OUT/run.log" \
    || { log "unpack of $1 failed"; exit 1; }
  if [ "$SPLIT" = "adapt" ]; then cat "$d"/*.txt > "$d/adapt.txt"; fi  # every split file the pack brought, joined
  unpacked[$1]=$d
}
declare -A run_data=()  # run name -> its --data folders (several packs are read as one dataset)
for r in $RUNS; do
  n=${r%%:*}
  [[ "$n" =~ ^[A-Za-z0-9_]+$ ]] || { echo "gpu_adapters.sh: run name '$n' in RUNS: use letters, digits and _ only" >&2; exit 2; }
  packs_var="AUG_PACK_$n"; packs="${!packs_var:-$AUG_PACK}"; folders=""
  for pk in $packs; do unpack "$pk"; folders+="$d "; done
  run_data[$n]=$folders
done
( while sleep 30; do for r in $RUNS; do n=${r%%:*}; log "$n $(tail -n 1 "$WORK/$n/train_log.jsonl" 2>/dev/null)"; done; done ) &
watcher=$!
mkdir -p "$WORK/logs"
pids=()
for r in $RUNS; do
  n=${r%%:*}; rest=${r#*:}; lam=${rest%%:*}; mu=0
  [ "$rest" != "$lam" ] && mu=${rest#*:}
  log "train $n: --data ${run_data[$n]}--env-pairs $lam --env-pairs-drift $mu --max-minutes $MINUTES --loader-workers $LOADER_WORKERS"
  "$PY" -m simdiff train adapters --data ${run_data[$n]} --split "$SPLIT" --init "$BACKBONE" --out "$WORK/$n" \
    --config "$CONFIG" --env-pairs "$lam" --env-pairs-drift "$mu" --device "$DEVICE" --text-table "$TEXT_TABLE" --max-minutes "$MINUTES" \
    --loader-workers "$LOADER_WORKERS" --no-progress ${ADAPTERS_INIT:+--adapters-init "$ADAPTERS_INIT"} \
    ${SEED:+--seed "$SEED"} > "$WORK/logs/$n.log" 2>&1 &
  pids+=($!)
done
status=0
for p in "${pids[@]}"; do wait "$p" || status=$?; done
kill "$watcher" 2>/dev/null
for r in $RUNS; do
  n=${r%%:*}
  tail -n 3 "$WORK/logs/$n.log" | tee -a "$OUT/run.log"
  if tar -C "$WORK/$n" -cf "$WORK/$n.tar" model train_log.jsonl train_config.json -C "$WORK/logs" "$n.log" \
      2>>"$OUT/run.log"; then
    if [ "$(stat -c %s "$WORK/$n.tar")" -le "$(( ${PART_KIB:-15360} * 1024 ))" ]; then
      mv "$WORK/$n.tar" "$OUT/$n.tar"
    else  # the device returns files of <= 16 MiB: cut, `cat NAME.tar.part_* > NAME.tar` joins them
      split -b "${PART_KIB:-15360}k" "$WORK/$n.tar" "$OUT/$n.tar.part_" && rm -f "$WORK/$n.tar"
    fi
  else
    log "$n: nothing to tar"
  fi
done
log "done status=$status"
exit "$status"
