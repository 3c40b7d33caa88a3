#!/usr/bin/env bash
# Session 64: cont.sh at lr 3e-4 (G63's adapters, batch 64, λ 10, μ 20, seed 64), snapshots every 400 steps, screened.
set -u
cd /work/scratch/s64
. /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
for S in 400 800 1200; do
  nice -n 5 python -m simdiff train adapters --data aug_weakg aug_gen aug_wind --split adapt --init $M --adapters-init $M \
    --out ad64_lr3 --config ad_cpu_lr3_config.json --steps $S \
    --text-table /work/main/.gpu/captions.safetensors --no-progress --loader-workers 1 || exit 1
  rm -rf snap_lr3_$S; cp -r ad64_lr3/model snap_lr3_$S; cp $M/sampling.json snap_lr3_$S/
  echo "[$(date -u +%H:%M)] step $S exported"
  (cd /work/main && python /work/scratch/s64/fl_screen.py /work/scratch/s64/snap_lr3_$S 2>&1 | grep "foot_lock 1.0")
done
