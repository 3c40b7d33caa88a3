#!/usr/bin/env bash
# Session 72, information after rule 84 (no rule): train84.sh with aug_lowloc listed once (TAG=b LOWLOC=1), snapshots
# 150 and 300, each screened like rule 84's snapshots (glide_screen.py, size_screen.py; X83's sampling).
set -u
R=/work/main/reports/training/s72_lowloc; O=/work/scratch/s72; S71=/work/main/reports/training/s71_split
TAG=b LOWLOC=1 SNAPS="150 300" bash $R/train84.sh > $O/train84b.log 2>&1 || exit 1
. /work/main/.venv/bin/activate
for S in 150 300; do
  F=$O/X84b_$S; rm -rf $F; cp -r $O/snap_b$S $F; cp /work/scratch/s71/models/X83_model/sampling.json $F/
  nice -n 5 python $S71/glide_screen.py $F | tee -a $R/glides.log
  nice -n 5 python $S71/size_screen.py $F | tee -a $R/sizes.log
done
echo "[$(date -u +%H:%M)] screen84b done"
