# Rule 66 (session 59): train X15sgww (as X15sg with aug_wind listed twice), then stage A (the later stages: next
# session).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s59; R=reports/training/s59_overlap; M=$O/X15sgww_model
R56=reports/training/s56_source_anchored; R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
mkdir -p $O
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15sgww %e s" python -m simdiff train adapters --targets source-anchored --twin-frames overlap --pair-twins wind \
    --drift-pairs wind --data $S/aug_weakg $S/aug_gen $S/aug_wind $S/aug_wind /work/scratch/s58/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/ad66 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 66 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad66/train_log.jsonl $R/train_log_X15sgww.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad66/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="126 127" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sgww_se4_fb3_js32_s126 $M 4
python $R57/stage_a55.py $S/eval11/A_X15sgww_se4_fb3_js32_s126 | tee -a $R/rule66_stages.txt | grep -q PASS \
  || { echo "rule 66: A failed"; exit 0; }
echo "rule 66: A passed (C', B, C+, T: next session)"
