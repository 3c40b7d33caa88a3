# Session 67: more simulator replays of the flight clips at the low end of gravity (g_z in [-2.5, -1.2], where the
# check asks its question at -1.6): aug_weakg's command (session 42) with a narrower range and a fresh seed.
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
nice -n 5 simdiff data augment --corpus $S/corpus3 --out /work/scratch/s67/aug_lowg --split train_flight --share-mirrors \
  --conditions 8 --factors gravity --gravity-range -2.5 -1.2 --no-retime --max-pose-d-l2 6.586 --workers 2 --seed 67 \
  --no-progress
