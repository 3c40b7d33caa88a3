#!/usr/bin/env bash
# Session 72: low-gravity replays of run and walk clips (train_runwalk = train clips whose captions say run/jog/sprint,
# plus train_walk150), Earth + 4 gravity draws in [-2.5, -1.2] per clip, retiming on (a weak-gravity rollout that falls
# is retried on the source slowed to the same Froude number), mirrors shared, aug_lowg's pose bound. Resumable.
cd /work/main; . .venv/bin/activate
nice -n 5 simdiff data augment --corpus /work/scratch/s39/corpus3 --out /work/scratch/s72/aug_lowloc --split train_runwalk \
  --share-mirrors --conditions 4 --factors gravity --gravity-range -2.5 -1.2 --max-pose-d-l2 6.586 --workers 2 --seed 72 \
  --no-progress
