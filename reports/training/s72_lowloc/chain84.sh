#!/usr/bin/env bash
# Session 72's chain for rule 84: after aug_lowloc.sh, its report and lowloc_stats.py; train84.sh; then rule 84's
# snapshot screens (glide_screen.py at g -1.6, and size_screen.py when no more than 1 of 16 runs glides).
set -u
R=/work/main/reports/training/s72_lowloc; O=/work/scratch/s72; S71=/work/main/reports/training/s71_split
while pgrep -f aug_lowloc.sh >/dev/null; do sleep 20; done
. /work/main/.venv/bin/activate
cp $O/aug_lowloc/all.txt $O/aug_lowloc/big79.txt
python $R/lowloc_stats.py $O/aug_lowloc /work/scratch/s39/corpus3 | tee -a $R/lowloc_stats.log
bash $R/train84.sh > $O/train84.log 2>&1 || exit 1
for S in 300 600; do
  F=$O/X84_$S; rm -rf $F; cp -r $O/snap_$S $F; cp /work/scratch/s71/models/X83_model/sampling.json $F/
  nice -n 5 python $S71/glide_screen.py $F | tee -a $R/glides.log
  if python -c "import json,sys; d=json.loads(open('$R/glides.log').read().splitlines()[-1]); sys.exit(0 if d['low_g']['glides']<=1 and d['low_g']['never_touch']==0 else 1)"; then
    nice -n 5 python $S71/size_screen.py $F | tee -a $R/sizes.log
  fi
done
echo "[$(date -u +%H:%M)] chain84 done"
