# Rule 68 (session 61): the gate on D5's probe, then stages C', A, B, C+, T in order, each only after the one before
# passed. D5 is trained and probed by: NAME=D5 INIT=/work/scratch/s61/D4_model FT=/work/scratch/s59/X15sg_model bash run_d4.sh
# Rule 69 runs the same with RULE=69 NAME=D6 AS=132 (run69.sh); rule 70 (session 62) with O, R and PROBE set (run70.sh);
# rule 71 (session 63) also with CPRIME, its stage-C' command (run71.sh).
set -u
cd /work/main; . .venv/bin/activate
RULE=${RULE:-68}; NAME=${NAME:-D5}; AS=${AS:-130}  # stage-A seeds AS and AS + 1
export SE=${SE:-4} FB=${FB:-3}  # the environment guidance and its fallback the stages sample with (rule 72: 3 and 2)
S=/work/scratch/s39; O=${O:-/work/scratch/s61}; R=${R:-reports/training/s61_distill}; M=$O/${NAME}_model
R56=reports/training/s56_source_anchored; R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
PROBE=${PROBE:-/work/scratch/s61_$(echo $NAME | tr D d).log}
python reports/training/s61_distill/gate68.py "$PROBE" $RULE | tee -a $R/rule${RULE}_stages.txt | grep -q "gate PASS" \
  || { echo "rule $RULE: gate failed"; exit 0; }
${CPRIME:-bash reports/training/s61_distill/cprime.sh} $NAME $M | tee -a $R/rule${RULE}_stages.txt | grep -q PASS || { echo "rule $RULE: C' failed"; exit 0; }
JS=32 ASEEDS="$AS $((AS + 1))" FB=$FB bash reports/training/s39_drift_gpu/check.sh A ${NAME}_se${SE}_fb${FB}_js32_s$AS $M $SE
python $R57/stage_a55.py $S/eval11/A_${NAME}_se${SE}_fb${FB}_js32_s$AS | tee -a $R/rule${RULE}_stages.txt | grep -q PASS \
  || { echo "rule $RULE: A failed"; exit 0; }
BN=${B_NAME:-$NAME}  # stage B samples Earth without fallback, so s_e does not enter: B_NAME reuses another name's draw
[ -f $S/eval11/B_$BN/check.json ] || ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B $BN $M $SE
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk$RULE.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py $BN $W | tee -a $R/rule${RULE}_stages.txt | grep -q PASS || { echo "rule $RULE: B failed"; exit 0; }
/usr/bin/time -f "stageC $NAME +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 $SE \
  $S/eval11/C_${NAME}_se${SE}/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS ${NAME}_se${SE} | tee -a $R/rule${RULE}_stages.txt | grep -q PASS || { echo "rule $RULE: C+ failed"; exit 0; }
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53  # t51.py's reference: the shipped model's test report
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
FB=$FB ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T ${NAME}_se${SE}_fb${FB} $M $SE
python $R56/t51.py T_${NAME}_se${SE}_fb${FB} | tee -a $R/rule${RULE}_stages.txt | grep -q "^SHIP" || { echo "rule $RULE: T failed"; exit 0; }
python - $RULE ${NAME}_se${SE}_fb${FB} <<'PY' | tee -a $R/rule${RULE}_stages.txt
import json, sys
j = round(json.load(open(f"/work/scratch/s39/eval11/T_{sys.argv[2]}/check.json"))["figures"]["jump_fraction"] * 96)
print(f"rule {sys.argv[1]}: T jumps {j} of 96 (bar 39):", "SHIP" if j >= 39 else "DO NOT SHIP")
PY
