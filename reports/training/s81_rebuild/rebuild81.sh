#!/usr/bin/env bash
# Session 81: the machine of session 80 was shut down mid-run and /work/scratch came back empty (corpus3, evaluator 1,
# the six simulator packs, X96 and X98 all gone; X95 is kept in git history). This rebuilds, each step skipped when its
# output is on disk, in the order rule 98's run needs them:
#   1. corpus3 and its split files (../s64_adapters_cpu/rebuild.sh's commands), hashes checked against session 55's;
#   2. the six packs (../s79_refit/packs.sh, unchanged);
#   3. X95 from history, then X96 = train96.sh's step-300 re-fit (seed 96); its sha256 must be bea4733b... (session 79),
#      else the script stops: rule 98's screens were drawn on those exact weights;
#   4. rule 98's chosen folder /work/scratch/s80/X98_t950_se1.1 (X96 with edit_t 950, env guidance 1.1, as screen98.sh
#      made it);
#   5. evaluator 1 (seed 0, 4 epochs), hash checked;
#   6. run98.sh (the gate, A, B, T, C+; its verdict lines go on in ../s80_env_scale/rule98_stages.txt).
set -u
cd /work/main; . .venv/bin/activate
R=reports/training; S=/work/scratch/s39; C=$S/corpus3
log() { echo "[$(date -u +%H:%M:%S)] $*"; }
mkdir -p $S /work/scratch/s79/models /work/scratch/s80 /work/scratch/s74  # s74: run87.sh writes its gate probe there
if [ ! -s $C/train_walk150.txt ]; then
  log "corpus3 start"
  nice -n 5 simdiff data build --shared ../shared/data --out $C --workers 2 --quiet || exit 1
  cp $R/s29_weak_gravity/train_flight_split.txt $C/train_flight.txt
  cp $R/s29_weak_gravity/train_sub300_split.txt $C/train_sub300.txt
  python $R/s40_walk_wind/walk_split.py $C > $C/train_walk150.tmp && mv $C/train_walk150.tmp $C/train_walk150.txt
  log "corpus3 done"
fi
(cd $S && grep " file corpus3/" /work/main/$R/s55_reference/sha256_rebuilt_s55.txt | sed 's/ file /  /' | sha256sum -c --quiet) \
  || { echo "rebuild81: corpus3 does not hash to session 55's files" >&2; exit 1; }
cmp -s $C/train_walk150.txt $R/s40_walk_wind/train_walk150_split.txt || echo "note: train_walk150 differs from s40's file"
# the packs only feed the re-fit: skipped when X96 is on disk (resume98.sh restores it from history)
[ -f /work/scratch/s79/models/X96/model.safetensors ] || bash $R/s79_refit/packs.sh || exit 1
X96=/work/scratch/s79/models/X96
if [ ! -f $X96/model.safetensors ]; then
  bash scripts/restore_report_weights.sh > /dev/null || exit 1
  log "re-fit start"; SNAPS=300 bash $R/s79_refit/train96.sh || exit 1; log "re-fit done"
  sha256sum /work/scratch/s79/snap_300/model.safetensors | grep -q ^bea4733bc95c8950 \
    || { echo "rebuild81: the step-300 re-fit hashes to $(sha256sum /work/scratch/s79/snap_300/model.safetensors | cut -c1-16), not X96's bea4733bc95c8950" >&2; exit 1; }
  rm -rf $X96.tmp && cp -r /work/scratch/s79/snap_300 $X96.tmp && mv $X96.tmp $X96
fi
F=/work/scratch/s80/X98_t950_se1.1
if [ ! -d $F ]; then
  rm -rf $F.tmp && cp -r $X96 $F.tmp
  python - "$F.tmp/sampling.json" 950 1.1 <<'PY'
import json, sys
p, et, se = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
d = json.load(open(p)); d["edit_t"], d["env_guidance"] = et, se
json.dump(d, open(p, "w"))
PY
  mv $F.tmp $F
fi
if [ ! -f $S/eval/model.safetensors ]; then
  log "evaluator start"
  nice -n 5 simdiff evaluate train-evaluator --corpus $C --out $S/eval --epochs 4 --no-progress || exit 1
  log "evaluator done"
fi
log "rule 98 stages"
bash $R/s80_env_scale/run98.sh
log "rebuild81 done"
