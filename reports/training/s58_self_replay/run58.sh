# Rule 58 (session 58): train X15ss (X15sa's adapters + 1,000 steps with aug_self), then stages A, C', B, C+, T; ship
# on a pass (ship58.py). Waits for run_aug.sh (one torch job at a time).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s58; R=reports/training/s58_self_replay; M=$O/X15ss_model
R57=reports/training/s57_pooled_a; R56=reports/training/s56_source_anchored
export SIMDIFF_SCRATCH=$S STEPS=50
while pgrep -f run_aug.sh > /dev/null; do sleep 20; done
grep -q AUG_DONE $O/aug.log || { echo "augmentation did not finish"; exit 1; }
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15ss %e s" python -m simdiff train adapters --targets source-anchored \
    --data $S/aug_weakg $S/aug_gen $S/aug_wind $O/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/ad58 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 58 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad58/train_log.jsonl $R/train_log_X15ss.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad58/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="110 111" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15ss_se4_fb3_js32_s110 $M 4
python $R57/stage_a55.py $S/eval11/A_X15ss_se4_fb3_js32_s110 | tee -a $R/rule58_stages.txt | grep -q PASS \
  || { echo "rule 58: A failed"; exit 0; }
SEEDS="1 2" /usr/bin/time -f "stageC12 X15ss %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_X15ss_se4/-1.6,0,0 $M || exit 1
python $R56/c51.py C12 X15ss_se4 | tee -a $R/rule58_stages.txt | grep -q PASS || { echo "rule 58: C' failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15ss $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk58.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py X15ss $W | tee -a $R/rule58_stages.txt | grep -q PASS || { echo "rule 58: B failed"; exit 0; }
/usr/bin/time -f "stageC X15ss +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15ss_se4/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS X15ss_se4 | tee -a $R/rule58_stages.txt | grep -q PASS || { echo "rule 58: C+ failed"; exit 0; }
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15ss_se4_fb3 $M 4
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
python reports/training/s52_runs_lowg/test_summary.py T_X15ss_se4_fb3 T_3_J40m_se4_fb3_c53 | tee -a $R/rule58_stages.txt
python $R56/t51.py T_X15ss_se4_fb3 | tee -a $R/rule58_stages.txt
T=${PIPESTATUS[0]}
J=$(python -c "import json; print(round(json.load(open('$S/eval11/T_X15ss_se4_fb3/check.json'))['figures']['jump_fraction'] * 96))")
echo "jumps $J of 96 (rule 58 bar 39)" | tee -a $R/rule58_stages.txt
[ $T -eq 0 ] && [ $J -ge 39 ] && echo "rule 58: SHIP" | tee -a $R/rule58_stages.txt || echo "rule 58: T failed, not shipped" | tee -a $R/rule58_stages.txt
