# Rule 49 (session 55): the reference anchor at the late steps only (t <= 500), J40m, a 0.25, alpha 0.5, s_e 4, fb 3.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s49/J40m_model; R=reports/training/s55_reference; P=$R/late_anchor.py
while pgrep -f run48.sh > /dev/null; do sleep 10; done
export SIMDIFF_SCRATCH=$S STEPS=50 ANCHOR=reference ANCHOR_ALPHA=0.25 ANCHOR_T0=500
for phi in -1.6,0,0 -9.81,10,0; do
  /usr/bin/time -f "stageC J40m_late25_se4 $phi %e s" python $P reports/training/s37_env_guidance/guard.py $phi 4 \
    $S/eval11/C_J40m_late25_se4/$phi $M
  python $R/stage_c48.py J40m_late25_se4 2>/dev/null | grep -F "phi $phi"
  [ "$phi" = -1.6,0,0 ] && { python - <<PY || { echo "stage C failed at g -1.6: no more"; exit 1; }
import json; g = json.load(open("$S/eval11/C_J40m_late25_se4/-1.6,0,0/check.json"))["test_split"]["generated"]
raise SystemExit(0 if g["r_precision_top3"]["mean"] >= 0.812 - 0.03 and g["fid"]["mean"] <= 1.25 * 2.33 else 1)
PY
  }
done
python $R/stage_c48.py J40m_late25_se4 || { echo "stage C failed: no B, A, T"; exit 1; }
PYWRAP=$P AA=0.25 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_late25 $M 4
W=$(cd reports/training/s53_extrapolate && PROBE_ANCHOR=reference PROBE_ANCHOR_ALPHA=0.25 python ../s55_reference/late_anchor.py walk_probe.py $M | tee /dev/stderr | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R/stage_b49.py J40m_late25 $W || { echo "stage B failed: no A, T"; exit 1; }
PYWRAP=$P AA=0.25 FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_late25_se4_fb3 $M 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_J40m_late25_se4_fb3 || { echo "stage A failed: no T"; exit 1; }
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53 && cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
PYWRAP=$P AA=0.25 FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T J40m_late25_se4_fb3 $M 4
python reports/training/s52_runs_lowg/test_summary.py T_J40m_late25_se4_fb3 T_3_J40m_se4_fb3_c53
