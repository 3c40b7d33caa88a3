#!/usr/bin/env bash
# Session 79: rebuild the six simulator packs X88's adapters were trained on (their scratch copies were gone), with
# their original commands and seeds (s42_jump_jog/run.sh, s67_ballistic/aug_lowg.sh, s72_lowloc/aug_lowloc.sh,
# s74_sim_reference/aug_lowgen.sh), into /work/scratch/s79; then the split files train88.sh read (`big79`):
#   aug_lowg, aug_weakg: big_split.py --min-apex 0.1 over their first_try split (session 69; "adapt" = first_try);
#   aug_wind: first_try; aug_gen: half_split.py of first_try (session 63's packed half); aug_lowloc, aug_lowgen: all.
# Each `simdiff data augment` resumes where it stopped; run again after a crash.
set -u
cd /work/main; . .venv/bin/activate
C=/work/scratch/s39/corpus3; O=/work/scratch/s79; R=reports/training
A="--share-mirrors --max-pose-d-l2 6.586 --workers 2 --no-progress"
log() { echo "[$(date -u +%H:%M:%S)] $*"; }
[ -s $C/train_runwalk.txt ] || python $R/s73_edit_scale/runwalk_split.py $C > $C/train_runwalk.txt
[ -s $C/train_lowgen.txt ] || python $R/s74_sim_reference/lowgen_split.py $C > $C/train_lowgen.txt
run() { local name=$1; shift; [ -s $O/$name/all.txt ] && { log "$name done before"; return 0; }
  log "$name start"; nice -n 5 simdiff data augment --corpus $C --out $O/$name "$@" || exit 1; log "$name end"; }
run aug_lowg   --split train_flight  --conditions 8 --factors gravity --gravity-range -2.5 -1.2 --no-retime $A --seed 67
run aug_weakg  --split train_flight  --conditions 8 --factors gravity --gravity-range -5 -1 --no-retime $A --seed 0
run aug_wind   --split train_walk150 --conditions 4 --factors wind_x wind_y $A
run aug_lowgen --split train_lowgen  --conditions 2 --factors gravity --gravity-range -2.5 -1.2 $A --seed 74
run aug_lowloc --split train_runwalk --conditions 4 --factors gravity --gravity-range -2.5 -1.2 $A --seed 72
run aug_gen    --split train_sub300  --conditions 6 $A --seed 0
for d in aug_lowg aug_weakg; do cp $O/$d/first_try.txt $O/$d/adapt.txt; done
python $R/s69_bigjumps/big_split.py $O/aug_lowg $O/aug_weakg --min-apex 0.1 --from-split adapt
cp $O/aug_wind/first_try.txt $O/aug_wind/big79.txt
python $R/s63_deepen/half_split.py $O/aug_gen first_try > $O/aug_gen/big79.txt
for d in aug_lowloc aug_lowgen; do cp $O/$d/all.txt $O/$d/big79.txt; done
for d in aug_lowg aug_weakg aug_wind aug_gen aug_lowloc aug_lowgen; do
  echo "$d: all $(wc -w < $O/$d/all.txt), first_try $(wc -w < $O/$d/first_try.txt 2>/dev/null), big79 $(wc -w < $O/$d/big79.txt)"
done
log "packs ready"
