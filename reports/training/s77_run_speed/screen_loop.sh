#!/usr/bin/env bash
# Session 77 screen (not a rule; no split drawn): does a short fine-tune of X93's backbone on train_jumpx + the run
# loops move its 6 s runs? 300 steps of batch 64 on 2 CPU cores (lr 1e-4, EMA 0.99, seed 77), X93's adapters put back
# (extrapolate with lambda -1: backbone = the fine-tune's), then 8 samples per prompt at 120 frames, seed 700 (the
# length probe's seed). Needs /work/scratch/s77/c3loop (corpus3 + `simdiff data loop --types run --frames 120`).
set -eu
cd /work/main; . .venv/bin/activate
C=/work/scratch/s77/c3loop; W=/work/scratch/s77/screen; X=simdiff/assets/default_model
mkdir -p $W
[ -s $C/train_jumpx.txt ] || python reports/training/s41_jump_backbone/jump_split.py $C 8 > $C/train_jumpx.txt
[ -s $C/train_jumpx_loop.txt ] || { cat $C/train_jumpx.txt; python -c "
import json; print('\n'.join(r['id'] for r in json.load(open('$C/loops.json'))['looped']))"; } > $C/train_jumpx_loop.txt
simdiff train backbone --data $C --split train_jumpx_loop --init $X --out $W/run --steps 300 --batch-size 64 \
  --lr 1e-4 --seed 77 --ema --ema-decay 0.99 --save-every 50 --max-minutes 25 --no-progress
simdiff train extrapolate --model $X --parent $W/run/model --lam -1 --out $W/model
for m in shipped:$X loop300:$W/model; do
  for p in "a person runs forward" "a person jogs forward" "a person walks forward" "a person jumps forward"; do
    o="$W/samples/${m%%:*}/${p// /_}"
    [ -f "$o/generation.json" ] || simdiff generate "$p" --model "${m#*:}" --frames 120 --num-samples 8 --seed 700 \
      --format npy --no-video -q --out "$o" > /dev/null
  done
done
python - "$W/samples" <<'PY'
import glob, sys
import numpy as np
from simdiff.eval.model_check.detect import jump_stats, root_speed
for d in sorted(glob.glob(sys.argv[1] + "/*/*")):
    j = [np.load(f) for f in sorted(glob.glob(d + "/sample*_joints.npy"))]
    s = np.percentile([root_speed(x) for x in j], [25, 50, 75]).round(2)
    print("/".join(d.split("/")[-2:]), len(j), "speed Q1/median/Q3", s, "jumps", sum(bool(jump_stats(x)["jump"]) for x in j))
PY
