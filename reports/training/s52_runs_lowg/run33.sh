# Rule 33's runs (rule33.txt committed first): the package's cleanup 3 and glide counts, shipped weights J40m, s_e 3.
set -e
cd /work/main
S=/work/scratch/s39
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40m_se3_drop /work/scratch/s49/J40m_model 3
