# Rule 36 stage A (session 53): X1 (passed stage B; X1.5 failed it under rule 37), shipped settings s_e 4 fallback 3.
set -u
cd /work/main
FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X1_se4_fb3 /work/scratch/s53/wx1 4
python reports/training/s52_runs_lowg/stage_a.py /work/scratch/s39/eval11/A_J40m_se4_fb3 /work/scratch/s39/eval11/A_X1_se4_fb3
