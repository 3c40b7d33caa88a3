# Rule 47: stage A of J40m_aa25 with fallback 2 (after rule 46's stage C), then stage T with the package.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s49/J40m_model; R=reports/training/s54_refit
while pgrep -f run46.sh > /dev/null; do sleep 10; done
python $R/stage_c.py J40m_aa25_se4 || { echo "stage C failed: no T"; exit 0; }
/usr/bin/time -f "stageA J40m_aa25_se4_fb2 %e s" python benchmarks/model_check.py --model $M --corpus $S/corpus3 \
  --evaluator $S/eval --split val --n 32 --seeds 100 101 --workers 2 --jump-samples 16 --speed-samples 8 \
  --steps 50 --guidance 2.5 --alpha 0.5 --foot-lock 1 --env-guidance 4 --anchor backbone --anchor-alpha 0.25 \
  --env-guidance-fallback 2 --threads 2 --out $S/eval11/A_J40m_aa25_se4_fb2 -q
python $R/stage_a_pass.py $S/eval11/A_J40m_aa25_se4_fb2 || { echo "stage A failed: no T"; exit 0; }
/usr/bin/time -f "stageT J40m_aa25_se4_fb2 %e s" python benchmarks/model_check.py --model $M --corpus $S/corpus3 \
  --evaluator $S/eval --split test --n 256 --seeds 0 1 2 3 4 --workers 2 --jump-samples 16 --speed-samples 8 \
  --steps 50 --guidance 2.5 --alpha 0.5 --foot-lock 1 --env-guidance 4 --anchor backbone --anchor-alpha 0.25 \
  --env-guidance-fallback 2 --also-evaluator $S/eval2 --also-evaluator $S/eval3 --threads 2 \
  --out $S/eval11/T_J40m_aa25_se4_fb2 -q
python reports/training/s52_runs_lowg/test_summary.py T_J40m_aa25_se4_fb2 T_3_J40m_se4_fb3_c53
