# Rule 69 (session 61): the gate on D6's probe, then stages C', A, B, C+, T in order, each only after the one before
# passed. D6 is trained and probed by: NAME=D6 INIT=/work/scratch/s61/D4_model FT=/work/scratch/s59/X15sg_model MINF=0.2 bash run_d4.sh
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s61; R=reports/training/s61_distill; M=$O/D6_model
R56=reports/training/s56_source_anchored; R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
PROBE=${PROBE:-/work/scratch/s61_d6.log}
python - "$PROBE" <<'PY' | tee -a $R/rule69_stages.txt | grep -q "gate PASS" || { echo "rule 69: gate failed"; exit 0; }
import json, sys
r = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")][-1]
wind = sum(v["downwind"] for v in r["wind"].values())
apex, ratio = r["gravity"]["apex_change_median_m"], r["moon"]["speed_ratio_median"]
ok = wind >= 60 and apex >= 0.32 and ratio >= 0.80
print(f"rule 69 gate: wind {wind}/64, apex change {apex:.3f} m, speed ratio {ratio:.3f} -> gate {'PASS' if ok else 'FAIL'}")
PY
if [ ! -f $S/eval11/C12_D6_se4/-1.6,0,0/check.json ]; then
  SEEDS="1 2" /usr/bin/time -f "stageC12 D6 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
    $S/eval11/C12_D6_se4/-1.6,0,0 $M || exit 1
fi
python $R56/c51.py C12 D6_se4 | tee -a $R/rule69_stages.txt | grep -q PASS || { echo "rule 69: C' failed"; exit 0; }
JS=32 ASEEDS="132 133" FB=3 bash reports/training/s39_drift_gpu/check.sh A D6_se4_fb3_js32_s132 $M 4
python $R57/stage_a55.py $S/eval11/A_D6_se4_fb3_js32_s132 | tee -a $R/rule69_stages.txt | grep -q PASS \
  || { echo "rule 69: A failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B D6 $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk69.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py D6 $W | tee -a $R/rule69_stages.txt | grep -q PASS || { echo "rule 69: B failed"; exit 0; }
/usr/bin/time -f "stageC D6 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_D6_se4/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS D6_se4 | tee -a $R/rule69_stages.txt | grep -q PASS || { echo "rule 69: C+ failed"; exit 0; }
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53  # t51.py's reference: the shipped model's test report
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T D6_se4_fb3 $M 4
python $R56/t51.py T_D6_se4_fb3 | tee -a $R/rule69_stages.txt | grep -q "^SHIP" || { echo "rule 69: T failed"; exit 0; }
python - <<'PY' | tee -a $R/rule69_stages.txt
import json
j = round(json.load(open("/work/scratch/s39/eval11/T_D6_se4_fb3/check.json"))["figures"]["jump_fraction"] * 96)
print(f"rule 69: T jumps {j} of 96 (bar 39):", "SHIP" if j >= 39 else "DO NOT SHIP")
PY
