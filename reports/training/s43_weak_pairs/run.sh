# Commands as run in session 45 (inputs rebuilt by ../s42_jump_jog/run.sh; S=/work/scratch/s39).
S=/work/scratch/s39
# rule 17 (base J40, rule 15 having adopted nothing): the split, then adapters 15 min, probe, stages A, B, C
python reports/training/s43_weak_pairs/weak_split.py $S/aug_weakg $S/aug_gen $S/aug_wind weak36
bash reports/training/s43_weak_pairs/chain.sh /work/scratch/s41/J40_model        # G17: not adopted
# control.txt: the same training on first_try (seed 43, 15 min), then stage A only
B=/work/scratch/s41/J40_model; O=/work/scratch/c17
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init $B \
  --adapters-init $B --out $O/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 43 --batch-size 64 --save-every 100 --device cpu \
  --text-table .gpu/captions.safetensors --max-minutes 15 --loader-workers 1 --no-progress
cp -r $O/ad/model $O/C17_model
bash reports/training/s39_drift_gpu/check.sh A C17 $O/C17_model
