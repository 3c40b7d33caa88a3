#!/usr/bin/env bash
# Rule 88's probe (rule88.txt; probe seeds only): X88 (/work/scratch/s74/snap_300 with X86's sampling) through
# glide_screen.py (seeds 7950+) and size_screen.py (seeds 7700+, n 48); then the text probe for X88 and, for comparison,
# X86: guard.py on rule 87's reference corpus (the simulator's low-g val replays) under g -1.6, seed 7300, n 128.
# Lines in probe88.log; the text probe's reports under /work/scratch/s74/probe_<name>.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s74_sim_reference; S71=reports/training/s71_split; M=/work/scratch/s74/models
mkdir -p $M
if [ ! -d $M/X88_model ]; then
  cp -r /work/scratch/s74/snap_300 $M/X88_model.tmp
  cp /work/scratch/s73/models/X86_model/sampling.json $M/X88_model.tmp/; mv $M/X88_model.tmp $M/X88_model
fi
export STEPS=50 W=2.5 ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 EDIT_T=900 ETA=1 BALLISTIC=
grep -q glide $R/probe88.log 2>/dev/null || nice -n 5 python $S71/glide_screen.py $M/X88_model | sed 's/^/glide X88 /' | tee -a $R/probe88.log
grep -q size $R/probe88.log 2>/dev/null || nice -n 5 python $S71/size_screen.py $M/X88_model | sed 's/^/size X88 /' | tee -a $R/probe88.log
for N in X88 X86; do
  F=/work/scratch/s74/probe_$N; MD=$M/${N}_model; [ $N = X86 ] && MD=/work/scratch/s73/models/X86_model
  [ -f $F/-1.6,0,0/check.json ] || SIMDIFF_SCRATCH=/work/scratch/s74/ref SEEDS=7300 \
    python reports/training/s37_env_guidance/guard.py -1.6,0,0 1 $F/-1.6,0,0 $MD > /dev/null
  echo -n "text $N seed 7300: "; python reports/training/s66_reference/v73.py text $F/-1.6,0,0 | tr '\n' ' ' | tee -a $R/probe88.log; echo | tee -a $R/probe88.log
done
