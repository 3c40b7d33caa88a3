#!/usr/bin/env bash
# Session 73: /work/scratch was lost, so X84 is rebuilt from its recipe: X81 (../s70_cross/train81.sh, 600 steps from
# G63's adapters, seed 70) then, once aug_lowloc exists, X84 (../s72_lowloc/train84.sh, 300 steps, seed 72). The
# weights' sha256 are compared with the ones rules 83/84 recorded (training is deterministic under its seed).
set -u
cd /work/main; . .venv/bin/activate
[ -d /work/scratch/s70/snap_600 ] || SNAPS=600 bash reports/training/s70_cross/train81.sh || exit 1
sha256sum /work/scratch/s70/snap_600/model.safetensors
while [ ! -f /work/scratch/s72/aug_lowloc/big79.txt ]; do sleep 30; done
SNAPS=300 bash reports/training/s72_lowloc/train84.sh || exit 1
sha256sum /work/scratch/s72/snap_300/model.safetensors
echo "[$(date -u +%H:%M)] X84 rebuilt"
