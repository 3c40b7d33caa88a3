#!/usr/bin/env bash
# Candidate for the next rule (session 77's plan; no rule written yet, nothing drawn): X93's backbone fine-tuned
# 1,200 steps of batch 64 on corpus3's train_jumpx + the run loops (screen_loop.sh's recipe, 4x longer, EMA 0.995,
# seed 94), checkpoints every 100 steps in /work/scratch/s77/train94 (re-running resumes there). About 2 h on 2 CPU
# cores; started in the background at the end of session 77. Then put X93's adapters back (extrapolate --lam -1, as
# screen_loop.sh does), re-fit them briefly if the rule asks, and judge runs by the caption-matched reference.
set -eu
cd /work/main; . .venv/bin/activate
C=/work/scratch/s77/c3loop
[ -s $C/train_jumpx_loop.txt ] || { echo "run screen_loop.sh first (it writes $C/train_jumpx_loop.txt)" >&2; exit 1; }
nice simdiff train backbone --data $C --split train_jumpx_loop --init simdiff/assets/default_model \
  --out /work/scratch/s77/train94 --steps 1200 --batch-size 64 --lr 1e-4 --seed 94 --ema --ema-decay 0.995 \
  --save-every 100 --no-progress
