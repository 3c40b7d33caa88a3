# Rule 44: X15a_a25 at s_e 12 fallback 6: stage A, then (on a pass) stage C; then stage T for the rule's candidate.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s54/X15a_model; R=reports/training/s54_refit
ALPHA=0.25 FB=6 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X15a_a25_se12_fb6 $M 12
if python $R/stage_a_pass.py $S/eval11/A_X15a_a25_se12_fb6; then
  STEPS=50 ALPHA=0.25 bash reports/training/s39_drift_gpu/stageC.sh X15a_a25_se12 $M 12
  if python $R/stage_c.py X15a_a25_se12; then
    echo "rule 44: X15a_a25 s_e 12 fallback 6 goes to stage T"
    ALPHA=0.25 FB=6 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15a_a25_se12_fb6 $M 12
    exit 0
  fi
fi
echo "rule 44: X15a s_e 5 fallback 3 goes to stages C and T"
STEPS=50 ALPHA=0.5 bash reports/training/s39_drift_gpu/stageC.sh X15a_se5 $M 5
python $R/stage_c.py X15a_se5 || { echo "X15a failed stage C"; exit 0; }
ALPHA=0.5 FB=3 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15a_se5_fb3 $M 5
