#!/usr/bin/env bash
# Rule 98's sampling screens (rule98.txt; probe seeds only): X96's weights (/work/scratch/s79/models/X96) with its
# sampling.json at edit_t in EDITS x env guidance s_e in SES, folders /work/scratch/s80/X98_t<ET>_se<SE>;
# glide_screen.py at g -1.6 (seeds 7950+), then size_screen.py (seeds 7700+, n 48) when select98.py --glides-ok passes;
# select98.py picks into choice98.txt. Lines in glides.log / sizes.log. Re-running skips screened folders.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s80_env_scale; S71=reports/training/s71_split; O=/work/scratch/s80; X=/work/scratch/s79/models/X96
mkdir -p $O
for ET in ${EDITS:-900 950}; do for SE in ${SES:-1 1.1 1.2}; do
  F=$O/X98_t${ET}_se$SE
  if [ ! -d $F ]; then
    rm -rf $F.tmp && cp -r $X $F.tmp
    python - "$F.tmp/sampling.json" "$ET" "$SE" <<'PY'
import json, sys
p, et, se = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
d = json.load(open(p)); d["edit_t"], d["env_guidance"] = et, se
json.dump(d, open(p, "w"))
PY
    mv $F.tmp $F
  fi
  grep -q "\"$F\"" $R/glides.log 2>/dev/null || nice -n 5 python $S71/glide_screen.py $F | tee -a $R/glides.log
  if python $R/select98.py $R --glides-ok $F; then
    grep -q "\"$F\"" $R/sizes.log 2>/dev/null || nice -n 5 python $S71/size_screen.py $F | tee -a $R/sizes.log
  fi
done; done
python $R/select98.py $R | tee $R/choice98.txt
