# Session 47: rules 21 and 22 (the guidance anchor). CPU, 2 cores, one job at a time; scratch as sessions 45-46
# (/work/scratch/s39: corpus3, eval; /work/scratch/s41/J40_model, a copy of simdiff/assets/default_model's weights).
S=/work/scratch/s39; M=/work/scratch/s41/J40_model; CK=reports/training/s39_drift_gpu/check.sh
# Stage B (val Earth, n 128, seeds 0 1). The backbone anchor at Earth is exactly alpha 0 (tested), so ALPHA=0:
ALPHA=0 STEPS=50 bash $CK B J40a0s50 $M                        # rule 21, w 2.5
for w in 3.0 3.5; do ALPHA=0 W=$w STEPS=50 bash $CK B J40a0w${w}s50 $M; done   # rule 22
python reports/training/s46_length/rule19_table.py $S/eval11/B_J40w2.5s50 $S/eval11/B_J40a0*
# Stage C (val n 128 seed 0, off Earth) and stage A (val seeds 100 101, response), the anchor on, w 3.0:
export SIMDIFF_SCRATCH=$S STEPS=50 W=3.0 ANCHOR=backbone
python reports/training/s37_env_guidance/guard.py -1.6,0,0 2 $S/eval11/C_J40anchor_w3.0/-1.6,0,0 $M
bash $CK A J40anchor_w3.0 $M
python reports/training/s37_env_guidance/guard.py -9.81,10,0 2 $S/eval11/C_J40anchor_w3.0/-9.81,10,0 $M
# Test split, descriptive (256 x 5, seeds 0-4), the anchor at w 3.0 with this session's evaluator:
ANCHOR=backbone W=3.0 STEPS=50 bash $CK T J40anchor_w3.0 $M
# A second evaluator (same recipe, seed 1) and the test split's text figures of both settings scored with it; the
# evaluator-free parts (jumps, speeds) are reused from the T runs (copied parts, same fingerprints):
simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval2 --epochs 4 --seed 1 --no-progress    # 202 s
for x in "J40w2.5s50 2.5 adapters" "J40anchor_w3.0 3.0 backbone"; do set -- $x
  mkdir -p $S/eval11/E2_$1 && cp -r $S/eval11/T_$1/parts $S/eval11/E2_$1/
  python benchmarks/model_check.py --model $M --corpus $S/corpus3 --evaluator $S/eval2 --split test --n 256 \
    --seeds 0 1 2 3 4 --no-response --jump-samples 16 --speed-samples 8 --steps 50 --guidance $2 --alpha 0.5 \
    --foot-lock 1 --env-guidance 2 --anchor $3 --threads 2 --out $S/eval11/E2_$1 -q                    # 14 min each
done
# Session 46's DDIM 20 test motions re-scored with the second evaluator (parts of T_J40 reused; 6 min):
mkdir -p $S/eval11/E2_J40 && cp -r $S/eval11/T_J40/parts $S/eval11/E2_J40/
python benchmarks/model_check.py --model $M --corpus $S/corpus3 --evaluator $S/eval2 --split test --n 256 --seeds 0 1 2 3 4 \
  --no-response --jump-samples 16 --speed-samples 8 --steps 20 --guidance 2.5 --alpha 0.5 --foot-lock 1 --env-guidance 2 \
  --threads 2 --out $S/eval11/E2_J40 -q
