# rule 18 confirmation runs: check.sh's stage A with fresh seeds 200 201
cd /work/main && . .venv/bin/activate
S=/work/scratch/s39
for nm in "K55 /work/scratch/s42/K55_model" "J40 /work/scratch/s41/J40_model"; do set -- $nm
  echo "== $(date +%H:%M:%S) A2 $1"
  /usr/bin/time -f "stageA2 $1 %e s" python benchmarks/model_check.py --model $2 --corpus $S/corpus3 --evaluator $S/eval \
    --split val --n 32 --seeds 200 201 --workers 2 --jump-samples 16 --speed-samples 8 --steps 20 --alpha 0.5 \
    --foot-lock 1 --env-guidance 2 --threads 2 --out $S/eval11/A2_$1 -q
done
echo "== $(date +%H:%M:%S) r18 done"
