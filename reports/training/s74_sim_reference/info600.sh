#!/usr/bin/env bash
# Session 74, information after rule 88 ended at C'' (no rule): does more training on the same mix move the low-g samples
# toward the simulator's replays? X88's run continued to 600 steps (train88.sh SNAPS="300 600"), X86's sampling, the text
# probe of probe88.sh (reference corpus under g -1.6, probe seed 7300, n 128). Line in probe88.log.
set -u
cd /work/main; . .venv/bin/activate
M=/work/scratch/s74/models/X88_600_model; F=/work/scratch/s74/probe_X88_600
[ -d $M ] || { cp -r /work/scratch/s74/snap_600 $M.tmp && cp /work/scratch/s73/models/X86_model/sampling.json $M.tmp/ && mv $M.tmp $M; }
export STEPS=50 W=2.5 ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 EDIT_T=900 ETA=1 BALLISTIC=
[ -f $F/-1.6,0,0/check.json ] || SIMDIFF_SCRATCH=/work/scratch/s74/ref SEEDS=7300 \
  python reports/training/s37_env_guidance/guard.py -1.6,0,0 1 $F/-1.6,0,0 $M > /dev/null
echo -n "text X88_600 seed 7300 (information): "
python reports/training/s66_reference/v73.py text $F/-1.6,0,0 | tr '\n' ' ' | tee -a reports/training/s74_sim_reference/probe88.log
echo | tee -a reports/training/s74_sim_reference/probe88.log
