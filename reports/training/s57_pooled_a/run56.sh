# Rule 56 (session 57): X15sa (lambda 1.5 backbone, source-anchored adapters) at val stages C', B, A, C+. Waits for
# run55.sh to finish (one torch job at a time).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s57; R=reports/training/s57_pooled_a; M=$O/X15sa_model; J=/work/scratch/s49/J40m_model
export SIMDIFF_SCRATCH=$S STEPS=50
while pgrep -f run55.sh > /dev/null; do sleep 30; done
[ -f $O/P/model.safetensors ] || for f in model.safetensors config.json sampling.json provenance.json; do
  mkdir -p $O/P; git show 1c859a7:simdiff/assets/default_model/$f > $O/P/$f; done
[ -f $O/wx1.5/model.safetensors ] || python -m simdiff train extrapolate --model $J --parent $O/P --lam 1.5 --out $O/wx1.5 || exit 1
if [ ! -f $M/model.safetensors ]; then
  /usr/bin/time -f "train X15sa %e s" python -m simdiff train adapters --targets source-anchored \
    --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
    --init $O/wx1.5 --adapters-init $J --out $O/ad56 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 55 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "training failed"; exit 1; }
  cp $O/ad56/train_log.jsonl $R/train_log_X15sa.jsonl 2>/dev/null
  rm -rf $M.tmp; cp -r $O/ad56/model $M.tmp; cp $J/sampling.json $M.tmp/; mv $M.tmp $M
fi
SEEDS="1 2" /usr/bin/time -f "stageC12 X15sa %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_X15sa_se4/-1.6,0,0 $M || exit 1
python reports/training/s56_source_anchored/c51.py C12 X15sa_se4 | tee -a $R/rule56_stages.txt | grep -q PASS \
  || { echo "rule 56: C' failed"; exit 0; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15sa $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a /work/scratch/s57/walk56.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R/b56.py X15sa $W | tee -a $R/rule56_stages.txt | grep -q PASS || { echo "rule 56: B failed"; exit 0; }
ASEEDS="104 105 106 107" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sa_se4_fb3_s104 $M 4
python $R/stage_a55.py $S/eval11/A_X15sa_se4_fb3_s104 | tee -a $R/rule56_stages.txt | grep -q PASS \
  || { echo "rule 56: A failed"; exit 0; }
/usr/bin/time -f "stageC X15sa +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_X15sa_se4/-9.81,10,0 $M || exit 1
python reports/training/s56_source_anchored/c51.py CPLUS X15sa_se4 | tee -a $R/rule56_stages.txt | grep -q PASS \
  && echo "rule 56: every val stage passed (next session: stage T)" || echo "rule 56: C+ failed"
