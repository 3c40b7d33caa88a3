# Rule 43 stage B: walk guard + val n 128 seeds 0 1 at alpha 0.25 for X1a and X15a (waits for run42A.sh).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s54; W=/work/scratch/s53
while pgrep -f run42A.sh > /dev/null; do sleep 15; done
for m in X1a:$W/X1a_model X15a:$O/X15a_model; do
  (cd reports/training/s53_extrapolate && PROBE_ALPHA=0.25 python walk_probe.py ${m#*:})
  ALPHA=0.25 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B ${m%%:*}_a25 ${m#*:} 4
done
python reports/training/s53_extrapolate/stage_b.py J40m_c3 X1a X1aB X15a X1a_a25 X15a_a25
