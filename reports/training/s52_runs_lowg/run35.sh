# Rule 35's stage A (rule35.txt committed first): cleanup 3, s_e 4 with the fallback to 3 for impossible samples.
set -e
cd /work/main
FALLBACK=3 PYWRAP=reports/training/s52_runs_lowg/fallback.py STEPS=50 \
  bash reports/training/s39_drift_gpu/check.sh A J40m_se4_fb3 /work/scratch/s49/J40m_model 4
