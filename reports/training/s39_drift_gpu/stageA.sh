# usage: stageA.sh NAME MODEL  -> selection seeds 100 101, val n 32, response on
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
/usr/bin/time -f "stageA $1 %e s" python benchmarks/model_check.py --model $2 --corpus $S/corpus3 --evaluator $S/eval \
  --split val --n 32 --seeds 100 101 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 --foot-lock 1 --env-guidance 2 --threads 2 \
  --workers 2 --out $S/eval11/A_$1 -q
