# Rule 60 (session 58): train X15sp2 (X15sp's adapters + 500 steps, mu 50), then stages A, C', B, C+, T; ship
# on a pass (ship58.py with X15sp2). Waits for run59.sh (one torch job at a time).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s58; R=reports/training/s58_self_replay; M=$O/X15sp2_model
R57=reports/training/s57_pooled_a; R56=reports/training/s56_source_anchored
export SIMDIFF_SCRATCH=$S STEPS=50
while pgrep -f run59.sh > /dev/null; do sleep 20; done
grep -q AUG_DONE $O/aug.log || { echo "augmentation did not finish"; exit 1; }
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15sp2 %e s" python -m simdiff train adapters --targets source-anchored --twin-frames prefix \
    --data $S/aug_weakg $S/aug_gen $S/aug_wind $O/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s58/X15sp_model --out $O/ad60 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 50 --seed 60 --batch-size 64 \
    --save-every 100 --device cpu --steps 500 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad60/train_log.jsonl $R/train_log_X15sp2.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad60/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="114 115" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sp2_se4_fb3_js32_s114 $M 4
python $R57/stage_a55.py $S/eval11/A_X15sp2_se4_fb3_js32_s114 | tee -a $R/rule60_stages.txt | grep -q PASS \
  || { echo "rule 60: A failed"; exit 0; }
SEEDS="1 2" /usr/bin/time -f "stageC12 X15sp2 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_X15sp2_se4/-1.6,0,0 $M || exit 1
python $R56/c51.py C12 X15sp2_se4 | tee -a $R/rule60_stages.txt | grep -q PASS || { echo "rule 60: C' failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15sp2 $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a $O/walk60.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R57/b56.py X15sp2 $W | tee -a $R/rule60_stages.txt | grep -q PASS || { echo "rule 60: B failed"; exit 0; }
/usr/bin/time -f "stageC X15sp2 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15sp2_se4/-9.81,10,0 $M || exit 1
python $R56/c51.py CPLUS X15sp2_se4 | tee -a $R/rule60_stages.txt | grep -q PASS || { echo "rule 60: C+ failed"; exit 0; }
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T X15sp2_se4_fb3 $M 4
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
python reports/training/s52_runs_lowg/test_summary.py T_X15sp2_se4_fb3 T_3_J40m_se4_fb3_c53 | tee -a $R/rule60_stages.txt
python $R56/t51.py T_X15sp2_se4_fb3 | tee -a $R/rule60_stages.txt
T=${PIPESTATUS[0]}
J=$(python -c "import json; print(round(json.load(open('$S/eval11/T_X15sp2_se4_fb3/check.json'))['figures']['jump_fraction'] * 96))")
echo "jumps $J of 96 (rule 60 bar 39)" | tee -a $R/rule60_stages.txt
[ $T -eq 0 ] && [ $J -ge 39 ] && echo "rule 60: SHIP" | tee -a $R/rule60_stages.txt || echo "rule 60: T failed, not shipped" | tee -a $R/rule60_stages.txt
