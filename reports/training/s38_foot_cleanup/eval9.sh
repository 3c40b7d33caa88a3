#!/bin/bash
cd /work/main && . .venv/bin/activate
while [ ! -f /work/scratch/s38/train9.end ]; do sleep 10; done
M=/work/scratch/s38/drift/model; E=/work/scratch/s29
/usr/bin/time -f "guard drift %e s" python benchmarks/model_check.py --model $M --corpus $E/corpus3 --evaluator $E/eval \
    --split val --n 32 --seeds 100 101 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 2 --threads 2 \
    --workers 2 --out /work/scratch/s38/eval9/guard -q
/usr/bin/time -f "val drift %e s" python benchmarks/model_check.py --model $M --corpus $E/corpus3 --evaluator $E/eval \
    --split val --n 128 --seeds 0 1 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 2 --threads 2 \
    --no-response --out /work/scratch/s38/eval9/val -q
echo done > /work/scratch/s38/eval9/DONE
