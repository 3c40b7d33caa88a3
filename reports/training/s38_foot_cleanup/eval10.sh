#!/bin/bash
cd /work/main && . .venv/bin/activate
M=/work/scratch/s38/drift/model; E=/work/scratch/s29
python benchmarks/model_check.py --model $M --corpus $E/corpus3 --evaluator $E/eval \
    --split val --n 32 --seeds 100 101 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 3 --threads 2 \
    --workers 2 --out /work/scratch/s38/eval10/sel -q
for phi in -1.6,0,0 -9.81,10,0; do python reports/training/s37_env_guidance/guard.py $phi 3 /work/scratch/s38/eval10/guard_$phi $M; done
echo done > /work/scratch/s38/eval10/DONE
