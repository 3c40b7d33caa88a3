# Rule 42 stage B: walk guard + val n 128 seeds 0 1 for X15a and X1aB (waits for run42train.sh).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s54; W=/work/scratch/s53
until grep -q TRAIN_DONE $O/train42.log; do sleep 20; done
(cd reports/training/s53_extrapolate && python walk_probe.py $O/X15a_model)
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15a $O/X15a_model 4
(cd reports/training/s53_extrapolate && PROBE_ANCHOR=backbone python walk_probe.py $W/X1a_model)
ANCHOR=backbone STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X1aB $W/X1a_model 4
python reports/training/s53_extrapolate/stage_b.py J40m_c3 X1 X1.5 X1a X15a X1aB
