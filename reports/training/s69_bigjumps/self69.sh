#!/usr/bin/env bash
# Session 69, rule 80's data: G63r5's own Earth jumps (= G63's backbone: reference anchor at anchor_alpha 0) on the
# train split's jump/hop/leap captions (s58's gen_jumps.py, 120 frames), replayed by the simulator at Earth and 12
# gravities in [-3.7, -1] (s58's run_aug.sh settings, seed 69). Resumable: each step is skipped when its output exists.
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s69
[ -f $O/selfgen/train.txt ] || nice -n 5 python reports/training/s58_self_replay/gen_jumps.py /work/scratch/s66/G63r5_model $S/corpus3 $O/selfgen
[ -f $O/aug_self63/env.json ] || /usr/bin/time -f "augment %e s" nice -n 5 python -m simdiff data augment --corpus $O/selfgen --out $O/aug_self63 --split train \
  --conditions 12 --factors gravity --gravity-range -3.7 -1 --no-retime --max-pose-d-l2 6.586 --workers 2 --seed 69 --no-progress
echo AUG_DONE
