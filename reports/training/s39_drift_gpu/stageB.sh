cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
/usr/bin/time -f "stageB $1 %e s" python benchmarks/model_check.py --model $2 --corpus $S/corpus3 --evaluator $S/eval \
  --split val --n 128 --seeds 0 1 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 2 --threads 2 \
  --no-response --out $S/eval11/B_$1 -q
