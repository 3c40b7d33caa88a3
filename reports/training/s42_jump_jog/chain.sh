# session 42 rule 15: backbone on train_mix, adapters 15 min, probes, stage B, A, C.
# STEPS / MINUTES bound the backbone leg; a second call resumes it from its latest checkpoint (run.sh: the first leg
# STEPS=4000 MINUTES=55, stopped by hand; then STEPS=1600 MINUTES=90, stopped at step 800 — rule15_outcome.txt)
cd /work/main && . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s42
while pgrep -f "train backbone --data" > /dev/null; do sleep 10; done   # an earlier leg still running
simdiff train backbone --data $S/corpus3 --split train_mix --init simdiff/assets/default_model \
  --out $O/bb --config configs/backbone_small_cpu.json --lr 1e-4 --seed 42 --batch-size 64 \
  --steps ${STEPS:-1600} --save-every 100 --device cpu --text-table .gpu/captions.safetensors --max-minutes ${MINUTES:-90} \
  --loader-workers 1 --no-progress
test -f $O/bb/model/model.safetensors || { echo "no backbone export"; exit 1; }
cp -r $O/bb/model $O/bb55_model
python reports/training/s41_jump_backbone/jump_probe.py $O/bb55_model '[{}]' 8
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init $O/bb55_model \
  --adapters-init simdiff/assets/default_model --out $O/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 42 --batch-size 64 --save-every 100 --device cpu \
  --text-table .gpu/captions.safetensors --max-minutes 15 --loader-workers 1 --no-progress
cp -r $O/ad/model $O/K55_model
python reports/training/s41_jump_backbone/jump_probe.py $O/K55_model '[{}]' 8
bash reports/training/s39_drift_gpu/check.sh B K55 $O/K55_model
bash reports/training/s39_drift_gpu/check.sh A K55 $O/K55_model
bash reports/training/s39_drift_gpu/stageC.sh K55 $O/K55_model
echo chain done
