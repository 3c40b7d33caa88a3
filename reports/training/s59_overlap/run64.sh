# Rule 64 (session 59): train X15sgw (X15sg + 400 steps with mu 50 on wind twins), then stages A, C', B, C+, T in
# order, each only after the one before passed.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s59; R=reports/training/s59_overlap; M=$O/X15sgw_model
R56=reports/training/s56_source_anchored; R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
mkdir -p $O
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15sgw %e s" python -m simdiff train adapters --targets source-anchored --twin-frames overlap --pair-twins wind \
    --drift-pairs wind --data $S/aug_weakg $S/aug_gen $S/aug_wind /work/scratch/s58/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s59/X15sg_model --out $O/ad64 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 50 --seed 64 --batch-size 64 \
    --save-every 100 --device cpu --steps 400 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad64/train_log.jsonl $R/train_log_X15sgw.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad64/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="122 123" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sgw_se4_fb3_js32_s122 $M 4
python $R57/stage_a55.py $S/eval11/A_X15sgw_se4_fb3_js32_s122 | tee -a $R/rule64_stages.txt | grep -q PASS \
  || { echo "rule 64: A failed"; exit 0; }
SEEDS="1 2" /usr/bin/time -f "stageC12 X15sgw %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_X15sgw_se4/-1.6,0,0 $M || exit 1
python $R56/c51.py C12 X15sgw_se4 | tee -a $R/rule64_stages.txt | grep -q PASS || { echo "rule 64: C' failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15sgw $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk64.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py X15sgw $W | tee -a $R/rule64_stages.txt | grep -q PASS || { echo "rule 64: B failed"; exit 0; }
/usr/bin/time -f "stageC X15sgw +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15sgw_se4/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS X15sgw_se4 | tee -a $R/rule64_stages.txt | grep -q PASS || { echo "rule 64: C+ failed"; exit 0; }
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53  # t51.py's reference: the shipped model's test report
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15sgw_se4_fb3 $M 4
python $R56/t51.py T_X15sgw_se4_fb3 | tee -a $R/rule64_stages.txt | grep -q "^SHIP" || { echo "rule 64: T failed"; exit 0; }
python - <<'PY' | tee -a $R/rule64_stages.txt
import json
j = round(json.load(open("/work/scratch/s39/eval11/T_X15sgw_se4_fb3/check.json"))["figures"]["jump_fraction"] * 96)
print(f"rule 64: T jumps {j} of 96 (bar 39):", "SHIP" if j >= 39 else "DO NOT SHIP")
PY
