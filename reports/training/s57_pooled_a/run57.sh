# Rule 57 (session 57): X15sa at stage A (the described run's folder), C'' (g -1.6, seeds 3 4 + 1 2), C+, T; ship on a pass.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; R=reports/training/s57_pooled_a; M=/work/scratch/s57/X15sa_model
export SIMDIFF_SCRATCH=$S STEPS=50
while pgrep -f run56_described.sh > /dev/null; do sleep 20; done
python $R/stage_a55.py $S/eval11/A_X15sa_se4_fb3_s104 | tee -a $R/rule57_stages.txt | grep -q PASS || { echo "rule 57: A failed"; exit 0; }
for pair in J40m_se4:simdiff/assets/default_model X15sa_se4:$M; do
  n=${pair%%:*}; m=${pair#*:}
  SEEDS="3 4" /usr/bin/time -f "stageC34 $n %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
    $S/eval11/C34_$n/-1.6,0,0 $m || exit 1
done
python $R/c57.py | tee -a $R/rule57_stages.txt | grep -q "C'': PASS" || { echo "rule 57: C'' failed"; exit 0; }
/usr/bin/time -f "stageC X15sa +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15sa_se4/-9.81,10,0 $M || exit 1
python reports/training/s56_source_anchored/c51.py CPLUS X15sa_se4 | tee -a $R/rule57_stages.txt | grep -q PASS \
  || { echo "rule 57: C+ failed"; exit 0; }
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15sa_se4_fb3 $M 4
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
python reports/training/s52_runs_lowg/test_summary.py T_X15sa_se4_fb3 T_3_J40m_se4_fb3_c53 | tee -a $R/rule57_stages.txt
python reports/training/s56_source_anchored/t51.py T_X15sa_se4_fb3 | tee -a $R/rule57_stages.txt
T=${PIPESTATUS[0]}
J=$(python -c "import json; print(round(json.load(open('$S/eval11/T_X15sa_se4_fb3/check.json'))['figures']['jump_fraction'] * 96))")
echo "jumps $J of 96 (rule 57 bar 39)" | tee -a $R/rule57_stages.txt
[ $T -eq 0 ] && [ $J -ge 39 ] && echo "rule 57: SHIP" | tee -a $R/rule57_stages.txt || echo "rule 57: T failed, not shipped" | tee -a $R/rule57_stages.txt
