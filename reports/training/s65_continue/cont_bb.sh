#!/usr/bin/env bash
# Session 65: G63's 8-layer backbone continued on CPU on corpus3's plain `train` split (no jump weighting), batch 64,
# lr 1e-4, EMA 0.999, seed 65; each 500-step export screened at alpha 0 (backbone alone) by bb_screen.py.
set -u
cd /work/scratch/s65
. /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
echo "[$(date -u +%H:%M)] baseline"
(cd /work/main && python /work/scratch/s65/bb_screen.py $M:0 /work/main/simdiff/assets/default_model:0)
for S in 500 1000 1500 2000 2500 3000 3500 4000; do
  nice -n 5 python -m simdiff train backbone --data /work/scratch/s64/corpus --split train --init $M \
    --out bb65 --config bb_cpu_config.json --steps $S \
    --text-table /work/main/.gpu/captions.safetensors --no-progress --loader-workers 1 || exit 1
  rm -rf snap_$S; cp -r bb65/model snap_$S
  echo "[$(date -u +%H:%M)] step $S exported"
  (cd /work/main && python /work/scratch/s65/bb_screen.py /work/scratch/s65/snap_$S:0)
done
