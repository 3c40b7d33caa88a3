#!/usr/bin/env bash
# Session 76 screen: X88 with the backbone at lambda 1/16 and 3/32, val Earth, n 16, seed 30 (never drawn), the
# prompt sections (96 jump samples, 16 speed samples per walk/run prompt); X88's sampling. Fresh seeds for any rule after.
cd /work/main; . .venv/bin/activate
for L in 0.0625 0.09375; do
  o=/work/scratch/s39/eval11/S_E${L}_s30; [ -f $o/check.json ] && continue
  /usr/bin/time -f "screen E$L %e s" python benchmarks/model_check.py --model /work/scratch/s75/models/E$L \
    --corpus /work/scratch/s39/corpus3 --evaluator /work/scratch/s39/eval --split val --n 16 --seeds 30 --no-response \
    --jump-samples 16 --speed-samples 16 --steps 50 --guidance 2.5 --alpha 0.925 --foot-lock 1 --env-guidance 1 \
    --anchor edit --anchor-alpha 0 --edit-t 900 --eta 1 --threads 2 --out $o -q
done
