#!/usr/bin/env bash
# Rule 84 (rule84.txt): X84 (train84.sh's snapshot chosen by the rule's screens; X83's sampling) through rule 73's stages
# (../s66_reference/run73.sh) with rule 84's gate (gate84.py, SPEED_BAR from lowloc_stats.py); stage-A seeds 158 159;
# lines in rule84_stages.txt. Needs /work/scratch/s72/models/X84_model. Stage B drawn anew (BDRAW).
cd /work/main
RULE=84 N=X84 MODELS=/work/scratch/s72/models R=reports/training/s72_lowloc SE=1 FB= AS=158 ANC=edit ALPHA=0.925 \
  EDIT_T=800 ETA=1 BDRAW=/work/scratch/s39/eval11/B_X84 GATE=reports/training/s72_lowloc/gate84.py \
  GATE_ARGS=${SPEED_BAR:?set SPEED_BAR} STAGES=${STAGES:-"gate A C' B C+ T"} bash reports/training/s66_reference/run73.sh
