#!/usr/bin/env bash
# Rule 84's adapters (rule84.txt): X81's 600-step crossed-twin adapters (/work/scratch/s70/snap_600, rule 83's weights)
# continued on CPU on rule 79's mix plus the session-72 low-gravity run and walk replays (aug_lowloc, listed 2x), the same
# recipe as X81 (train81.sh: crossed twins 0.5, overlap, pair-twins wind, drift-pairs wind, lambda 10, mu 20, batch 64),
# seed 72. Snapshots at SNAPS (default 300 600) exported to /work/scratch/s72/snap_S. Resumable: run again.
# Session 72's information run after rule 84: TAG=b LOWLOC=1 (aug_lowloc listed once; run folder ad84b, snap_bS).
set -u
cd /work/scratch/s67; . /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
TAG=${TAG:-}; LL=/work/scratch/s72/aug_lowloc; DATA="$LL $LL"; [ "${LOWLOC:-2}" = 1 ] && DATA=$LL
for S in ${SNAPS:-300 600}; do
  SNAP=/work/scratch/s72/snap_$TAG$S
  [ -d $SNAP ] && continue
  nice -n 5 python -m simdiff train adapters \
    --data aug_lowg aug_lowg aug_lowg aug_weakg aug_wind aug_gen $DATA \
    --split big79 --init $M --adapters-init /work/scratch/s70/snap_600 --out /work/scratch/s72/ad84$TAG \
    --config /work/main/reports/training/s67_ballistic/ad67_config.json --steps $S --seed 72 \
    --env-pairs 10 --env-pairs-drift 20 --twin-frames overlap --pair-twins wind --drift-pairs wind --cross-twins 0.5 \
    --text-table /work/main/.gpu/captions.safetensors --no-progress --loader-workers 1 || exit 1
  rm -rf $SNAP.tmp; cp -r /work/scratch/s72/ad84$TAG/model $SNAP.tmp; mv $SNAP.tmp $SNAP
  echo "[$(date -u +%H:%M)] step $S exported"
done
