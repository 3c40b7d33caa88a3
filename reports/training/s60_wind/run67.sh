# Rule 67 (session 60): train X15se (X15sa + aug_self, equal twin frames, --pair-twins wind), then stages A, C', B, C+, T in order, each
# only after the one before passed.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s60; R=reports/training/s60_wind; M=$O/X15se_model
R56=reports/training/s56_source_anchored; R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
mkdir -p $O
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15se %e s" python -m simdiff train adapters --targets source-anchored --pair-twins wind \
    --drift-pairs wind --data $S/aug_weakg $S/aug_gen $S/aug_wind /work/scratch/s58/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/ad67 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 70 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad67/train_log.jsonl $R/train_log_X15se.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad67/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="128 129" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15se_se4_fb3_js32_s128 $M 4
python $R57/stage_a55.py $S/eval11/A_X15se_se4_fb3_js32_s128 | tee -a $R/rule67_stages.txt | grep -q PASS \
  || { echo "rule 67: A failed"; exit 0; }
SEEDS="1 2" /usr/bin/time -f "stageC12 X15se %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_X15se_se4/-1.6,0,0 $M || exit 1
python $R56/c51.py C12 X15se_se4 | tee -a $R/rule67_stages.txt | grep -q PASS || { echo "rule 67: C' failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15se $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk67.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py X15se $W | tee -a $R/rule67_stages.txt | grep -q PASS || { echo "rule 67: B failed"; exit 0; }
/usr/bin/time -f "stageC X15se +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15se_se4/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS X15se_se4 | tee -a $R/rule67_stages.txt | grep -q PASS || { echo "rule 67: C+ failed"; exit 0; }
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53  # t51.py's reference: the shipped model's test report
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15se_se4_fb3 $M 4
python $R56/t51.py T_X15se_se4_fb3 | tee -a $R/rule67_stages.txt | grep -q "^SHIP" || { echo "rule 67: T failed"; exit 0; }
python - <<'PY' | tee -a $R/rule67_stages.txt
import json
j = round(json.load(open("/work/scratch/s39/eval11/T_X15se_se4_fb3/check.json"))["figures"]["jump_fraction"] * 96)
print(f"rule 67: T jumps {j} of 96 (bar 39):", "SHIP" if j >= 39 else "DO NOT SHIP")
PY
