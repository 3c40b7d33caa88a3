#!/usr/bin/env bash
# Rule 81's screen (rule81.txt): snapshot SNAP of X81 with the edit anchor at edit_t in TS (default 600 800), seeds 7700+,
# n 48 pairs (s67_ballistic/ballistic_screen.py); one JSON line each in screens.log. Then the fit probe (information).
set -u
SNAP=${SNAP:-600}; O=/work/scratch/s70; R=/work/main/reports/training/s70_cross
cd /work/main/reports/training/s67_ballistic; . /work/main/.venv/bin/activate
for T in ${TS:-600 800}; do
  F=$O/X81_${SNAP}_t$T; rm -rf $F; cp -r $O/snap_$SNAP $F
  cat > $F/sampling.json <<JSON
{"alpha": 1.0, "guidance": 2.5, "steps": 50, "sampler": "ddim", "foot_lock": 1.0, "env_guidance": 1.0,
 "anchor": "edit", "anchor_alpha": 0.0, "edit_t": $T}
JSON
  nice -n 5 python ballistic_screen.py $F --dump $O/dump81_${SNAP}_t$T.json | tee -a $R/screens.log
done
