# Rule 48 (session 55): evaluator check, then the reference anchor (J40m, a 0.25, alpha 0.5, s_e 4, fb 3): C, A, T.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s49/J40m_model; R=reports/training/s55_reference
while pgrep -f rebuild2.sh > /dev/null; do sleep 10; done
if ! python $R/repro.py; then   # the bases, re-measured on this scratch
  bash reports/training/s39_drift_gpu/stageC.sh J40m_se4 $M 4
  ALPHA=0.25 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_a25 $M 4
  python reports/training/s53_extrapolate/stage_b.py J40m_c3 J40m_a25
fi
export SIMDIFF_SCRATCH=$S STEPS=50 ANCHOR=reference ANCHOR_ALPHA=0.25
for phi in -1.6,0,0 -9.81,10,0; do
  /usr/bin/time -f "stageC J40m_ref25_se4 $phi %e s" python reports/training/s37_env_guidance/guard.py $phi 4 \
    $S/eval11/C_J40m_ref25_se4/$phi $M
done
python $R/stage_c48.py J40m_ref25_se4 || { echo "stage C failed: no A, no T"; exit 1; }
AA=0.25 FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_ref25_se4_fb3 $M 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_J40m_ref25_se4_fb3 || { echo "stage A failed: no T"; exit 1; }
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
AA=0.25 FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T J40m_ref25_se4_fb3 $M 4
python reports/training/s52_runs_lowg/test_summary.py T_J40m_ref25_se4_fb3 T_3_J40m_se4_fb3_c53
