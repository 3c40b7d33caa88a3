# Rule 41 (session 53): X1a stage B (+ walk guard), then stage A at s_e 6 and 5 (fallback 3).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s53
(cd reports/training/s53_extrapolate && python walk_probe.py $W/X1a_model)
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X1a $W/X1a_model 4
python reports/training/s53_extrapolate/stage_b.py J40m_c3 X1 X1a
for se in 6 5; do FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X1a_se${se}_fb3 $W/X1a_model $se; done
python reports/training/s52_runs_lowg/stage_a.py $S/eval11/A_J40m_se4_fb3 $S/eval11/A_X1a_se4_fb3 $S/eval11/A_X1a_se6_fb3 $S/eval11/A_X1a_se5_fb3
