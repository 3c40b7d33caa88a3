bash test.sh ws_d20 /work/scratch/s39/gpu/ws_d20/model
cd /work/main; . .venv/bin/activate; S=/work/scratch/s39
/usr/bin/time -f "test shipped %e s" python benchmarks/model_check.py --model /work/scratch/s39/shipped_s29_model --corpus $S/corpus3 --evaluator $S/eval \
  --split test --n 256 --seeds 0 1 2 3 4 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 2 --threads 2 \
  --no-response --out $S/eval11/T_shipped -q
echo ALLDONE
