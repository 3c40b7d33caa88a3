# 300 steps from X15sa, exported with EMA 0.99 (near the raw weights), then the probe: bash onset.sh VARIANT
#   sg    X15sg's recipe (aug_self, overlap, --pair-twins wind, --drift-pairs wind; seed 63)  -> ON300_model
#   sa    X15sa's recipe continued (no aug_self, equal frames, all pairs; seed 55)            -> ONsa300_model
#   ss    X15sa's recipe with aug_self (X15ss's recipe; seed 55)                              -> ONss300_model
#   sgx   X15sg's recipe without aug_self (seed 63)                                           -> ONgx300_model
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s60; SELF=/work/scratch/s58/aug_self
SG="--twin-frames overlap --pair-twins wind --drift-pairs wind"
case "${1:?variant: sg sa ss sgx}" in
  sg) OPTS="$SG"; DATA="$SELF"; SEED=63; NAME=ON300; OUT=adON ;;
  sa) OPTS=""; DATA=""; SEED=55; NAME=ONsa300; OUT=adON2 ;;
  ss) OPTS=""; DATA="$SELF"; SEED=55; NAME=ONss300; OUT=adON3 ;;
  sgx) OPTS="$SG"; DATA=""; SEED=63; NAME=ONgx300; OUT=adON4 ;;
  *) echo "unknown variant $1 (sg sa ss sgx)"; exit 2 ;;
esac
python -m simdiff train adapters --targets source-anchored $OPTS \
    --data $S/aug_weakg $S/aug_gen $S/aug_wind $DATA --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/$OUT \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed $SEED --batch-size 64 \
    --ema-decay 0.99 --save-every 100 --device cpu --steps 300 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress || exit 1
M=$O/${NAME}_model; rm -rf $M; cp -r $O/$OUT/model $M; cp /work/scratch/s57/X15sa_model/sampling.json $M/
python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 $M
