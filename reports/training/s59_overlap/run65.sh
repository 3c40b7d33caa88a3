# Rule 65 (session 59): train X15sg0 (as X15sg with mu 0), then stages A, C', B, C+ in order, each only after the
# one before passed (T: next session).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s59; R=reports/training/s59_overlap; M=$O/X15sg0_model
R56=reports/training/s56_source_anchored; R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
mkdir -p $O
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15sg0 %e s" python -m simdiff train adapters --targets source-anchored --twin-frames overlap --pair-twins wind \
    --data $S/aug_weakg $S/aug_gen $S/aug_wind /work/scratch/s58/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/ad65 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 0 --seed 65 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad65/train_log.jsonl $R/train_log_X15sg0.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad65/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="124 125" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sg0_se4_fb3_js32_s124 $M 4
python $R57/stage_a55.py $S/eval11/A_X15sg0_se4_fb3_js32_s124 | tee -a $R/rule65_stages.txt | grep -q PASS \
  || { echo "rule 65: A failed"; exit 0; }
SEEDS="1 2" /usr/bin/time -f "stageC12 X15sg0 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_X15sg0_se4/-1.6,0,0 $M || exit 1
python $R56/c51.py C12 X15sg0_se4 | tee -a $R/rule65_stages.txt | grep -q PASS || { echo "rule 65: C' failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15sg0 $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk65.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py X15sg0 $W | tee -a $R/rule65_stages.txt | grep -q PASS || { echo "rule 65: B failed"; exit 0; }
/usr/bin/time -f "stageC X15sg0 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15sg0_se4/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS X15sg0_se4 | tee -a $R/rule65_stages.txt | grep -q PASS || { echo "rule 65: C+ failed"; exit 0; }
echo "rule 65: A, C', B, C+ passed (T: next session)"
