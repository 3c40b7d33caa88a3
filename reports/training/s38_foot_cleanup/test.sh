cd /work/main && . .venv/bin/activate
S=/work/scratch/s38; E=/work/scratch/s29
/usr/bin/time -f "test clean %e s" python benchmarks/model_check.py --model simdiff/assets/default_model --corpus $E/corpus3 --evaluator $E/eval \
    --split test --n 256 --seeds 0 1 2 3 4 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 2 --threads 2 \
    --workers 2 --out $S/test/clean -q
echo done > $S/test/DONE
