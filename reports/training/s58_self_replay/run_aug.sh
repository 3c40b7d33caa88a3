# Session 58: the model's own Earth jumps (gen_jumps.py) replayed by the simulator at Earth and 12 gravities in
# [-3.7, -1] m/s^2 (Mars to below the Moon), the filter settings of aug_weakg (reports/training/s55_reference).
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s58
[ -f $O/selfgen/train.txt ] || python reports/training/s58_self_replay/gen_jumps.py /work/scratch/s57/X15sa_model $S/corpus3 $O/selfgen
/usr/bin/time -f "augment %e s" python -m simdiff data augment --corpus $O/selfgen --out $O/aug_self --split train \
  --conditions 12 --factors gravity --gravity-range -3.7 -1 --no-retime --max-pose-d-l2 6.586 --workers 2 --seed 0 --no-progress
echo AUG_DONE
