#!/usr/bin/env bash
# Session 76 screen 2: X90 (lambda 1/8) at text guidance 3.0 and 3.5 (walks and runs drawn apart?), the same val
# probe as screen93.sh (n 16, seed 30, 96 jump samples, 16 speed samples per walk/run prompt); otherwise X90's sampling.
cd /work/main; . .venv/bin/activate
for W in 3.5 3.0; do
  o=/work/scratch/s39/eval11/S_X90w${W}_s30; [ -f $o/check.json ] && continue
  /usr/bin/time -f "screen X90 w$W %e s" python benchmarks/model_check.py --model /work/scratch/s75/models/X90_model \
    --corpus /work/scratch/s39/corpus3 --evaluator /work/scratch/s39/eval --split val --n 16 --seeds 30 --no-response \
    --jump-samples 16 --speed-samples 16 --steps 50 --guidance $W --alpha 0.925 --foot-lock 1 --env-guidance 1 \
    --anchor edit --anchor-alpha 0 --edit-t 900 --eta 1 --threads 2 --out $o -q
done
