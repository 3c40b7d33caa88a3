# Rule 36 stage T (session 53), run only after stage A passes: X1 on the test split, three evaluators, shipped settings
# (s_e 4, fallback 3, cleanup 3), nothing reused (new weights); then the paired summary against the shipped report.
set -u
cd /work/main
S=/work/scratch/s39
FB=3 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_X1_se4_fb3 /work/scratch/s53/wx1 4
python reports/training/s52_runs_lowg/test_summary.py T_3_X1_se4_fb3 T_3_J40m_se4_fb3
