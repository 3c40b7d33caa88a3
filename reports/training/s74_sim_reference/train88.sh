#!/usr/bin/env bash
# Session 74: X88's adapters. X84's weights (/work/scratch/s72/snap_300, rebuilt in session 73) continued on CPU on X84's
# mix plus the general-content low-gravity replays (aug_lowgen, listed 2x), X84's recipe (crossed twins 0.5, overlap,
# pair-twins wind, drift-pairs wind, lambda 10, mu 20, batch 64), seed 74; the captions encoded by the text encoder
# (the packed caption table lacks aug_lowgen's). Snapshots at SNAPS (default 300) exported to /work/scratch/s74/snap_S.
# Resumable: run again.
set -u
cd /work/scratch/s67; . /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model; LL=/work/scratch/s72/aug_lowloc; LG=/work/scratch/s74/aug_lowgen
for S in ${SNAPS:-300}; do
  SNAP=/work/scratch/s74/snap_$S
  [ -d $SNAP ] && continue
  nice -n 5 python -m simdiff train adapters \
    --data aug_lowg aug_lowg aug_lowg aug_weakg aug_wind aug_gen $LL $LL $LG $LG \
    --split big79 --init $M --adapters-init /work/scratch/s72/snap_300 --out /work/scratch/s74/ad88 \
    --config /work/main/reports/training/s67_ballistic/ad67_config.json --steps $S --seed 74 \
    --env-pairs 10 --env-pairs-drift 20 --twin-frames overlap --pair-twins wind --drift-pairs wind --cross-twins 0.5 \
    --no-progress --loader-workers 1 || exit 1
  rm -rf $SNAP.tmp; cp -r /work/scratch/s74/ad88/model $SNAP.tmp; mv $SNAP.tmp $SNAP
  echo "[$(date -u +%H:%M)] step $S exported"
done
