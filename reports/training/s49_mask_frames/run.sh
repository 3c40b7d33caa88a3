# Session 49's commands, in order (scratch S=/work/scratch/s39 from sessions 39-48: corpus3 with train_jumpy,
# aug_weakg, aug_gen, aug_wind, evaluators eval / eval2 / eval3, J40's stage runs in eval11/). Rule 25 (rule25.txt)
# was written and committed before these ran.
S=/work/scratch/s39; W=/work/scratch/s49
simdiff train backbone --data $S/corpus3 --split train_jumpy --init simdiff/assets/default_model --mask-frames \
  --out $W/bb --config configs/backbone_small_cpu.json --lr 1e-4 --seed 48 --batch-size 64 \
  --steps 2400 --save-every 100 --device cpu --text-table .gpu/captions.safetensors \
  --loader-workers 1 --no-progress                                                # J48's 2,400 steps
cp -r $W/bb/model $W/bb_model
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init $W/bb_model \
  --adapters-init simdiff/assets/default_model --out $W/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 48 --batch-size 64 --save-every 100 --device cpu --steps 1400 \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress          # J48's 1,400 steps
cp -r $W/ad/model $W/M49_model
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B M49 $W/M49_model   # rule 25
# rule 26 (written after rule 25's outcome, before these): the shipped weights and J48's with the mask at inference only
for pair in "J40m simdiff/assets/default_model" "J48m $W/../s48/J48_model"; do set -- $pair
  cp -r $2 $W/$1_model   # then "mask_frames": true in $W/$1_model/config.json
  STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B $1 $W/$1_model
done                                                                              # 317 s, 345 s
# adopted: simdiff/assets/default_model/config.json "mask_frames": true; the test split once, three evaluators
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m simdiff/assets/default_model   # 1,603 s
python reports/training/s49_mask_frames/paired.py > reports/training/s49_mask_frames/paired.txt
python benchmarks/bench_generate.py --json reports/training/s49_mask_frames/bench_generate.json
# screen, no rule: guidance 3.5 and 2.0 on the shipped (masked) model, val stage B
for w in 3.5 2.0; do W=$w STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_w$w simdiff/assets/default_model; done
