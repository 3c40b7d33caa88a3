#!/usr/bin/env bash
# Session 64: corpus3 and the three evaluators rebuilt (s55_reference/run.sh's commands), niced under the training.
set -eu
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; mkdir -p $S /work/scratch/s49
cp -r simdiff/assets/default_model /work/scratch/s49/J40m_model
nice -n 15 simdiff data build --shared ../shared/data --out $S/corpus3 --workers 2 --quiet
cp reports/training/s29_weak_gravity/train_flight_split.txt $S/corpus3/train_flight.txt
cp reports/training/s29_weak_gravity/train_sub300_split.txt $S/corpus3/train_sub300.txt
python reports/training/s40_walk_wind/walk_split.py $S/corpus3 > $S/corpus3/train_walk150.txt
python reports/training/s42_jump_jog/mix_split.py $S/corpus3 8 16 1 > $S/corpus3/train_jumpy.txt
echo "[$(date -u +%H:%M)] corpus done"
nice -n 15 simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval --epochs 4 --no-progress
nice -n 15 simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval2 --epochs 4 --seed 1 --no-progress
nice -n 15 simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval3 --epochs 4 --seed 2 --no-progress
echo "[$(date -u +%H:%M)] evaluators done"
