# Session 48's commands, in order (scratch S=/work/scratch/s39 from sessions 39-47: corpus3, aug_weakg, aug_gen,
# aug_wind, evaluator eval, J40's stage runs in eval11/). Rule 24 (rule24.txt) was written before these ran.
S=/work/scratch/s39; W48=/work/scratch/s48
python reports/training/s42_jump_jog/mix_split.py $S/corpus3 8 16 1 > $S/corpus3/train_jumpy.txt   # jumps 8x, in place 8+16 = 24x, jogs 1x
simdiff train backbone --data $S/corpus3 --split train_jumpy --init simdiff/assets/default_model \
  --out $W48/bb --config configs/backbone_small_cpu.json --lr 1e-4 --seed 48 --batch-size 64 \
  --steps 3000 --save-every 100 --device cpu --text-table .gpu/captions.safetensors --max-minutes 40 \
  --loader-workers 1 --no-progress                                               # 40 min
cp -r $W48/bb/model $W48/bb_model
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init $W48/bb_model \
  --adapters-init simdiff/assets/default_model --out $W48/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 48 --batch-size 64 --save-every 100 --device cpu \
  --text-table .gpu/captions.safetensors --max-minutes 15 --loader-workers 1 --no-progress   # 15 min
cp -r $W48/ad/model $W48/J48_model
python reports/training/s41_jump_backbone/jump_probe.py $W48/J48_model '[{"steps": 50}]' 8       # a screen
STEPS=50 bash reports/training/s39_drift_gpu/check.sh B J48 $W48/J48_model                        # rule 24
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J48 $W48/J48_model                        # rule 24, if B passes
# descriptive, after rule 24's outcome: stage B re-scored with the second evaluator (session 47's eval2, seed 1)
for pair in "J40w2.5s50 simdiff/assets/default_model" "J48 $W48/J48_model"; do set -- $pair
  python benchmarks/model_check.py --model $2 --corpus $S/corpus3 --evaluator $S/eval2 --split val --n 128 --seeds 0 1 \
    --no-response --jump-samples 16 --speed-samples 8 --steps 50 --guidance 2.5 --alpha 0.5 --foot-lock 1 \
    --env-guidance 2 --anchor adapters --threads 2 --out $S/eval11/B2_$1 -q
done
# screens of the text side and of exact training captions (outputs: caption_neighbours.txt, prompt_probe.txt)
python reports/training/s48_inplace/caption_neighbours.py $S/corpus3 .gpu/captions.safetensors \
  "a person jumps up in place" "a person jumps up and down" "a person does a long jump" > reports/training/s48_inplace/caption_neighbours.txt
for m in simdiff/assets/default_model $W48/J48_model; do echo "# $m"
  python reports/training/s48_inplace/prompt_probe.py $m "a person jumps up." "a person jumps high." "a person jumps up in place"
done > reports/training/s48_inplace/prompt_probe.txt
# the new --also-evaluator against the two separate runs above (same figures, one generation)
python benchmarks/model_check.py --model simdiff/assets/default_model --corpus $S/corpus3 --evaluator $S/eval \
  --also-evaluator $S/eval2 --split val --n 128 --seeds 0 1 --no-response --jump-samples 16 --speed-samples 8 \
  --steps 50 --guidance 2.5 --alpha 0.5 --foot-lock 1 --env-guidance 2 --anchor adapters --threads 2 \
  --out $S/eval11/BB_J40w2.5s50 -q
# a third evaluator and the shipped model's test split scored by all three in one run (session 46's parts copied in)
simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval3 --epochs 4 --seed 2 --no-progress   # 243 s
python benchmarks/model_check.py --model simdiff/assets/default_model --corpus $S/corpus3 --evaluator $S/eval \
  --also-evaluator $S/eval2 --also-evaluator $S/eval3 --split test --n 256 --seeds 0 1 2 3 4 --no-response \
  --jump-samples 16 --speed-samples 8 --steps 50 --guidance 2.5 --alpha 0.5 --foot-lock 1 --env-guidance 2 \
  --anchor adapters --threads 2 --out $S/eval11/T3_J40w2.5s50 -q                                         # 1,054 s
# session 47's anchor test motions scored by evaluators 1 and 3 (session 47's parts copied in), then the paired table
python benchmarks/model_check.py --model /work/scratch/s41/J40_model --corpus $S/corpus3 --evaluator $S/eval \
  --also-evaluator $S/eval3 --split test --n 256 --seeds 0 1 2 3 4 --no-response --jump-samples 16 --speed-samples 8 \
  --steps 50 --guidance 3.0 --alpha 0.5 --foot-lock 1 --env-guidance 2 --anchor backbone --threads 2 \
  --out $S/eval11/T3_J40anchor_w3.0 -q                                                                  # 953 s
python reports/training/s48_inplace/paired.py
