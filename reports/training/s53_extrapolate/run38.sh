# Rule 38 stage A (session 53): X1 at s_e 5 and 6, fallback 3.
set -u
cd /work/main
for se in 5 6; do FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X1_se${se}_fb3 /work/scratch/s53/wx1 $se; done
python reports/training/s52_runs_lowg/stage_a.py /work/scratch/s39/eval11/A_J40m_se4_fb3 /work/scratch/s39/eval11/A_X1_se4_fb3 \
  /work/scratch/s39/eval11/A_X1_se5_fb3 /work/scratch/s39/eval11/A_X1_se6_fb3
