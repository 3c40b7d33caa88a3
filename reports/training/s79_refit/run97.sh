#!/usr/bin/env bash
# Rule 97 (rule97.txt): train96.sh on to step 600, then A, B, T and C+ with run87.sh's stages on that export (X97);
# verdict lines in rule97_stages.txt. Re-running skips every step and draw on disk.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s79_refit; W=/work/scratch/s79; OUT=$R/rule97_stages.txt; M=$W/models/X97
if [ ! -f $M/model.safetensors ]; then
  SNAPS="300 600" bash $R/train96.sh || exit 1
  mkdir -p $W/models && rm -rf $M.tmp && cp -r $W/snap_600 $M.tmp && mv $M.tmp $M
  echo "X97 = step 600 ($(sha256sum $M/model.safetensors | cut -c1-16))" | tee -a $OUT
fi
RULE=97 N=X97 M=$M AS=174 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="12 13" B_VERDICT="python reports/training/s78_captioned/v94.py earth" \
  T_VERDICT="python reports/training/s78_captioned/v94.py test" STAGES="${STAGES:-A B T Cplus}" STAGES_OUT=$OUT \
  bash reports/training/s74_sim_reference/run87.sh
