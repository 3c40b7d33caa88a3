# Session 50's commands, in order (scratch S=/work/scratch/s39 from sessions 39-49: corpus3 with train_jumpy,
# aug_weakg, aug_gen, aug_wind, evaluators eval / eval2 / eval3, J40m's runs in eval11/; M49 in /work/scratch/s49).
# Rule 27 (rule27.txt) was written and committed before these ran.
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s50
simdiff train backbone --data $S/corpus3 --split train_jumpy --init /work/scratch/s49/M49_model --mask-frames \
  --out $W/bb --config configs/backbone_small_cpu.json --lr 1e-4 --lr-schedule cosine --seed 50 --batch-size 64 \
  --steps 2600 --save-every 100 --device cpu --text-table .gpu/captions.safetensors \
  --loader-workers 1 --no-progress
rm -rf $W/bb_model; cp -r $W/bb/model $W/bb_model
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init $W/bb_model \
  --adapters-init /work/scratch/s49/M49_model --out $W/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 50 --batch-size 64 --save-every 100 --device cpu --steps 1000 \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress
rm -rf $W/M50_model; cp -r $W/ad/model $W/M50_model
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B M50 $W/M50_model   # rule 27 stage B
