#!/usr/bin/env bash
# Session 74: low-gravity replays of general content (train_lowgen: lowgen_split.py, 250 train clips without flight,
# run or jump captions, with their mirrors), Earth + 2 gravity draws in [-2.5, -1.2] per clip, retiming on, mirrors
# shared, aug_lowg's pose bound, seed 74; big79.txt = every kept pair. Resumable.
cd /work/main; . .venv/bin/activate
C=/work/scratch/s39/corpus3; O=/work/scratch/s74/aug_lowgen
[ -s $C/train_lowgen.txt ] || python reports/training/s74_sim_reference/lowgen_split.py $C > $C/train_lowgen.txt
nice -n 5 simdiff data augment --corpus $C --out $O --split train_lowgen --share-mirrors --conditions 2 --factors gravity \
  --gravity-range -2.5 -1.2 --max-pose-d-l2 6.586 --workers 2 --seed 74 --no-progress && cp $O/all.txt $O/big79.txt
