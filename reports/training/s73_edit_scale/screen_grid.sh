#!/usr/bin/env bash
# Rules 85 and 86's sampling screens (probe seeds only): X84's rebuilt weights (/work/scratch/s72/snap_300) with X83's
# sampling at edit_t in EDITS x env_guidance s_e in SES, folders /work/scratch/s73/<NAMEFMT> (NAMEFMT uses $ET and $SE);
# glide_screen.py at g -1.6 (seeds 7950+), then size_screen.py (seeds 7700+, n 48) when no more than 1 of 16 runs glides
# and none never touches; select85.py (with SELECT_ARGS) picks into CHOICE. Lines in glides.log / sizes.log.
set -u
R=/work/main/reports/training/s73_edit_scale; S71=/work/main/reports/training/s71_split; O=/work/scratch/s73
. /work/main/.venv/bin/activate; mkdir -p $O
for ET in $EDITS; do for SE in $SES; do
  F=$O/$(eval echo "$NAMEFMT")
  if [ ! -d $F ]; then
    cp -r /work/scratch/s72/snap_300 $F.tmp
    echo "{\"alpha\": 0.925, \"guidance\": 2.5, \"steps\": 50, \"sampler\": \"ddim\", \"foot_lock\": 1.0, \"env_guidance\": $SE, \"anchor\": \"edit\", \"anchor_alpha\": 0.0, \"edit_t\": $ET, \"eta\": 1.0}" > $F.tmp/sampling.json
    mv $F.tmp $F
  fi
  grep -q "\"$F\"" $R/glides.log 2>/dev/null || nice -n 5 python $S71/glide_screen.py $F | tee -a $R/glides.log
  if python $R/select85.py $R --glides-ok $F; then
    grep -q "\"$F\"" $R/sizes.log 2>/dev/null || nice -n 5 python $S71/size_screen.py $F | tee -a $R/sizes.log
  fi
done; done
python $R/select85.py $R ${SELECT_ARGS:-} | tee $R/$CHOICE
