#!/usr/bin/env bash
# Session 64: G63's adapters continued on CPU (batch 64, lr 1e-4, λ 10, μ 20, seed 64), snapshots every 600 steps,
# each screened for run/jog speed at Earth (fl_screen.py draws, seeds 3100+).
set -u
cd /work/scratch/s64
. /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
for S in 600 1200 1800 2400 3000 3600 4200 4800; do
  nice -n 5 python -m simdiff train adapters --data aug_weakg aug_gen aug_wind --split adapt --init $M --adapters-init $M \
    --out ad64 --config ad_cpu_config.json --steps $S --env-pairs 10 --env-pairs-drift 20 \
    --text-table /work/main/.gpu/captions.safetensors --no-progress --loader-workers 1 || exit 1
  rm -rf snap_$S; cp -r ad64/model snap_$S; cp $M/sampling.json snap_$S/
  echo "[$(date -u +%H:%M)] step $S exported"
  (cd /work/main && python /work/scratch/s64/fl_screen.py /work/scratch/s64/snap_$S 2>&1 | grep "foot_lock 1.0")
done
