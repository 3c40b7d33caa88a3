# Rule 46: J40m with the text guidance at alpha 0.25 and the environment term at alpha 0.5 (anchor_alpha.py): B, A, C.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s49/J40m_model; R=reports/training/s54_refit
export ANCHOR_ALPHA=0.25
(cd reports/training/s53_extrapolate && PROBE_ALPHA=0.25 python walk_probe.py $M)
ALPHA=0.25 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_a25 $M 4
python reports/training/s53_extrapolate/stage_b.py J40m_c3 J40m_a25
PYWRAP=$R/anchor_alpha.py ANCHOR=backbone FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40m_aa25_se4_fb3 $M 4
python $R/stage_a_pass.py $S/eval11/A_J40m_aa25_se4_fb3
export SIMDIFF_SCRATCH=$S STEPS=50 ANCHOR=backbone
for phi in -1.6,0,0 -9.81,10,0; do
  python $R/anchor_alpha.py reports/training/s37_env_guidance/guard.py $phi 4 $S/eval11/C_J40m_aa25_se4/$phi $M
done
python $R/stage_c.py J40m_aa25_se4
