#!/usr/bin/env bash
# Rule 87's reference: every val clip of corpus3 replayed by the tracker under g in [-1.65, -1.55] (Earth + 1 draw per
# clip), retiming on as in the training data, mirrors shared, aug_lowg's pose bound. Resumable.
cd /work/main; . .venv/bin/activate
nice -n 5 simdiff data augment --corpus /work/scratch/s39/corpus3 --out /work/scratch/s74/val_g16 --split val --share-mirrors \
  --conditions 1 --factors gravity --gravity-range -1.65 -1.55 --max-pose-d-l2 6.586 --workers 2 --seed 74 --no-progress
