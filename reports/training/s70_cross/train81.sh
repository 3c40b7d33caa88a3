#!/usr/bin/env bash
# Rule 81's adapters X81 (rule81.txt): G63's adapters continued on CPU with crossed twins (--cross-twins 0.5), rule 79's
# mix (split big79, aug_lowg listed 3x), rule 63's twin handling (overlap, pair-twins wind, drift-pairs wind), lambda 10,
# mu 20, batch 64, seed 70. Snapshots at SNAPS (default 600 1200) exported to /work/scratch/s70/snap_S (sampling.json
# written by the screen script). Resumable: run again.
set -u
cd /work/scratch/s67; . /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
for S in ${SNAPS:-600 1200}; do
  nice -n 5 python -m simdiff train adapters --data aug_lowg aug_lowg aug_lowg aug_weakg aug_wind aug_gen --split big79 \
    --init $M --adapters-init $M --out /work/scratch/s70/ad81 \
    --config /work/main/reports/training/s67_ballistic/ad67_config.json --steps $S --seed 70 \
    --env-pairs 10 --env-pairs-drift 20 --twin-frames overlap --pair-twins wind --drift-pairs wind --cross-twins 0.5 \
    --text-table /work/main/.gpu/captions.safetensors --no-progress --loader-workers 1 || exit 1
  rm -rf /work/scratch/s70/snap_$S; cp -r /work/scratch/s70/ad81/model /work/scratch/s70/snap_$S
  echo "[$(date -u +%H:%M)] step $S exported"
done
