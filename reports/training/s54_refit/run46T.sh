# Rule 46 stage T (after its stages A and C pass): test n 256 x seeds 0-4, response on, with the package's
# --anchor backbone --anchor-alpha 0.25 (bit-identical to anchor_alpha.py's patch on a checked sample).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s49/J40m_model; R=reports/training/s54_refit
while pgrep -f run46.sh > /dev/null; do sleep 10; done
python $R/stage_a_pass.py $S/eval11/A_J40m_aa25_se4_fb3 || { echo "stage A failed: no T"; exit 0; }
python $R/stage_c.py J40m_aa25_se4 || { echo "stage C failed: no T"; exit 0; }
/usr/bin/time -f "stageT J40m_aa25_se4_fb3 %e s" python benchmarks/model_check.py --model $M --corpus $S/corpus3 \
  --evaluator $S/eval --split test --n 256 --seeds 0 1 2 3 4 --workers 2 --jump-samples 16 --speed-samples 8 \
  --steps 50 --guidance 2.5 --alpha 0.5 --foot-lock 1 --env-guidance 4 --anchor backbone --anchor-alpha 0.25 \
  --env-guidance-fallback 3 --also-evaluator $S/eval2 --also-evaluator $S/eval3 --threads 2 \
  --out $S/eval11/T_J40m_aa25_se4_fb3 -q
python reports/training/s52_runs_lowg/test_summary.py T_J40m_aa25_se4_fb3 T_3_J40m_se4_fb3
