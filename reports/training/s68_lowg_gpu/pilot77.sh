#!/usr/bin/env bash
# Rule 77's model A77 (rule77.txt): G63's adapters continued on CPU from G63 with the pair term at lambda 30, session 67's
# data (aug_weakg, aug_gen first half, aug_wind, aug_lowg; cont67.sh) and recipe otherwise, 600 steps of batch 64,
# then exported with rule 74's sampling.json and screened (ballistic_screen.py, seeds 7700+). Resumable: run again.
set -u
cd /work/scratch/s67; . /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
R=/work/main/reports/training/s68_lowg_gpu
nice -n 5 python -m simdiff train adapters --data aug_weakg aug_gen aug_wind aug_lowg --split adapt --init $M \
  --adapters-init $M --out /work/scratch/s68/ad77 --config $R/ad77_config.json --steps 600 \
  --env-pairs 30 --env-pairs-drift 20 --text-table /work/main/.gpu/captions.safetensors --no-progress \
  --loader-workers 1 || exit 1
rm -rf /work/scratch/s68/A77_model; cp -r /work/scratch/s68/ad77/model /work/scratch/s68/A77_model
cp /work/scratch/s66/G63r5_model/sampling.json /work/scratch/s68/A77_model/
echo "[$(date -u +%H:%M)] A77 exported"
(cd /work/main/reports/training/s67_ballistic && python ballistic_screen.py /work/scratch/s68/A77_model \
  --dump /work/scratch/s68/dump77.json) | tee -a $R/screens.log
