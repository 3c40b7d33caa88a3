# Rule 34's runs (rule34.txt committed first): cleanup 3, shipped weights, s_e 3.5; the test split only if A passes.
set -e
cd /work/main
S=/work/scratch/s39
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40m_se3.5_drop /work/scratch/s49/J40m_model 3.5
