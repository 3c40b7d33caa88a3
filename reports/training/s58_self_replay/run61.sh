# Rule 61 (session 58): train X15sw (X15sa's adapters + 1,000 steps with aug_self, --twin-frames prefix, --drift-pairs
# wind), then stage A (val seeds 116 117, JS=32). Waits for run60.sh (one torch job at a time).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s58; R=reports/training/s58_self_replay; M=$O/X15sw_model
R57=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
while pgrep -f run60.sh > /dev/null; do sleep 20; done
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15sw %e s" python -m simdiff train adapters --targets source-anchored --twin-frames prefix \
    --drift-pairs wind --data $S/aug_weakg $S/aug_gen $S/aug_wind $O/aug_self --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/ad61 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 61 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad61/train_log.jsonl $R/train_log_X15sw.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad61/model $M.tmp; cp /work/scratch/s57/X15sa_model/sampling.json $M.tmp/; mv $M.tmp $M
fi
JS=32 ASEEDS="116 117" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sw_se4_fb3_js32_s116 $M 4
python $R57/stage_a55.py $S/eval11/A_X15sw_se4_fb3_js32_s116 | tee -a $R/rule61_stages.txt | grep -q PASS \
  && echo "rule 61: A passed (C', B, C+, T: next session)" || echo "rule 61: A failed"
