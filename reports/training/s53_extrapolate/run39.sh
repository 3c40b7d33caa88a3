# Rule 39 (session 53): X0.5, walk guard + stage B, then stage A if B passes (judged by hand before T).
set -u
cd /work/main
S=/work/scratch/s39; M=/work/scratch/s53
(cd $M && nice python walk_probe.py wx0.5)
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X0.5 $M/wx0.5 4
python reports/training/s53_extrapolate/stage_b.py J40m_c3 X1 X0.5
FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X0.5_se4_fb3 $M/wx0.5 4
python reports/training/s52_runs_lowg/stage_a.py $S/eval11/A_J40m_se4_fb3 $S/eval11/A_X1_se4_fb3 $S/eval11/A_X0.5_se4_fb3
