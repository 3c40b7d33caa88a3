# Rule 33's test run (after its stage A passed): the package's cleanup 3 and glide counts, shipped weights, s_e 3.
set -e
cd /work/main
S=/work/scratch/s39
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m_se3_drop /work/scratch/s49/J40m_model 3
