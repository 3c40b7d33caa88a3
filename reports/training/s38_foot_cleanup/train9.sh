#!/bin/bash
cd /work/main && . .venv/bin/activate
while [ ! -f /work/scratch/s38/test/DONE ]; do sleep 10; done
date > /work/scratch/s38/train9.start
nice -n 5 simdiff train adapters --data /work/scratch/s29/aug_weakg /work/scratch/s29/aug_gen --split s37_loco --out /work/scratch/s38/drift \
  --config reports/training/s29_weak_gravity/train_config_pair10.json --init simdiff/assets/default_model \
  --adapters-init simdiff/assets/default_model --batch-size 32 --lr 1e-4 --seed 37 --steps 40000 --save-every 500 \
  --env-pairs-drift 50 --max-minutes 45 --no-progress
date > /work/scratch/s38/train9.end
