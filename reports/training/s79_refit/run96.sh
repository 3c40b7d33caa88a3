#!/usr/bin/env bash
# Rule 96 (rule96.txt): packs.sh, then train96.sh to step 300 and rule 84's gate on it, then (if it failed) on to step
# 600 and its gate, then A, B, T and
# C+ with run87.sh's stages on the first that passed (X96); verdict lines in rule96_stages.txt. Re-running skips
# every step and draw on disk.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s79_refit; W=/work/scratch/s79; OUT=$R/rule96_stages.txt
stamp() { echo "[$(date -u +%H:%M)] $*" >&2; }
[ -s $W/aug_lowgen/big79.txt ] && [ -s $W/aug_gen/big79.txt ] || bash $R/packs.sh || exit 1
M=$W/models/X96
if [ ! -f $M/model.safetensors ]; then
  for s in 300 600; do
    SNAPS=$s bash $R/train96.sh || exit 1
    P=/work/scratch/s74/X96_${s}_probe.log
    grep -qs "^{" $P || python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 $W/snap_$s > $P 2>&1
    L=$(python reports/training/s72_lowloc/gate84.py $P 96 0.209)
    echo "step $s ($(sha256sum $W/snap_$s/model.safetensors | cut -c1-16)): $L" | tee -a $OUT
    if echo "$L" | grep -q "gate PASS"; then
      mkdir -p $W/models && rm -rf $M.tmp && cp -r $W/snap_$s $M.tmp && mv $M.tmp $M
      echo "X96 = step $s" | tee -a $OUT; break
    fi
  done
  [ -f $M/model.safetensors ] || { echo "rule 96: no export passed the gate" | tee -a $OUT; exit 0; }
fi
RULE=96 N=X96 M=$M AS=172 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="10 11" B_VERDICT="python reports/training/s78_captioned/v94.py earth" \
  T_VERDICT="python reports/training/s78_captioned/v94.py test" STAGES="${STAGES:-A B T Cplus}" STAGES_OUT=$OUT \
  bash reports/training/s74_sim_reference/run87.sh
