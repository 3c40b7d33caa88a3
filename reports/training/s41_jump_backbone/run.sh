# Session 41's commands, in order (scratch S=/work/scratch/s39 from sessions 39-40: corpus3, aug_weakg, aug_gen,
# aug_wind, evaluator eval, the shipped model's stage runs in eval11/)
S=/work/scratch/s39
python reports/training/s41_jump_backbone/jump_probe.py simdiff/assets/default_model \
  '[{}, {"eta": 1.0}, {"eta": 1.0, "steps": 50}, {"guidance": 5.0}, {"foot_lock": 0.0}]' 8   # the shipped model, before
python reports/training/s41_jump_backbone/jump_split.py $S/corpus3 8 > $S/corpus3/train_jumpx.txt
simdiff train backbone --data $S/corpus3 --split train_jumpx --init simdiff/assets/default_model \
  --out /work/scratch/s41/bb --config configs/backbone_small_cpu.json --lr 1e-4 --seed 41 --batch-size 64 \
  --steps 3000 --save-every 100 --device cpu --text-table .gpu/captions.safetensors --max-minutes 40 \
  --loader-workers 1 --no-progress                                               # 40 min, 1,500 steps
cp -r /work/scratch/s41/bb/model /work/scratch/s41/bb40_model
adapters() {  # the shipped adapters warm-started on the new backbone; a second call resumes the run (J40b)
  simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init /work/scratch/s41/bb40_model \
    --adapters-init simdiff/assets/default_model --out /work/scratch/s41/ad --config configs/adapters_paired_gpu_finetune.json \
    --env-pairs 10 --env-pairs-drift 20 --seed 41 --batch-size 64 --save-every 100 --device cpu \
    --text-table .gpu/captions.safetensors --max-minutes 15 --loader-workers 1 --no-progress
  cp -r /work/scratch/s41/ad/model /work/scratch/s41/$1_model
}
python reports/training/s41_jump_backbone/jump_probe.py /work/scratch/s41/bb40_model '[{}]' 8
adapters J40                                                                     # 15 min, 1,000 steps
python reports/training/s41_jump_backbone/jump_probe.py /work/scratch/s41/J40_model '[{}]' 8
bash reports/training/s39_drift_gpu/check.sh B J40 /work/scratch/s41/J40_model   # rule 13
bash reports/training/s39_drift_gpu/check.sh A J40 /work/scratch/s41/J40_model
bash reports/training/s39_drift_gpu/stageC.sh J40 /work/scratch/s41/J40_model
bash reports/training/s39_drift_gpu/check.sh T J40 /work/scratch/s41/J40_model
adapters J40b                                                                    # rule 14: 15 more min, to step 2,000
bash reports/training/s39_drift_gpu/check.sh A J40b /work/scratch/s41/J40b_model
simdiff train export-backbone --model /work/scratch/s39/cw20_model --out /work/scratch/s41/bb_shipped
python reports/training/s41_jump_backbone/jump_probe.py /work/scratch/s41/bb_shipped '[{}]' 8   # the shipped backbone alone
