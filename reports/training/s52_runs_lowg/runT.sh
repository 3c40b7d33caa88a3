# Rule 32's test run (after stage A passed): the package's foot cleanup 3 (drop_floating inside clean_feet), s_e 4.
set -e
cd /work/main
S=/work/scratch/s39
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m_se4_drop /work/scratch/s49/J40m_model 4
