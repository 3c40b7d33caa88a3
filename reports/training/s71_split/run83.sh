#!/usr/bin/env bash
# Rule 83 (rule83.txt): X83 (X81's 600-step weights; session-71 edit anchor, edit t 800, alpha 0.925, DDIM eta 1, s_e 1,
# no fallback) through rule 73's stages (../s66_reference/run73.sh), stage-A seeds 156 157; lines in rule83_stages.txt.
# Needs /work/scratch/s71/models/X83_model (snap_600 + the sampling.json of rule83.txt). Stage B drawn anew (BDRAW).
cd /work/main
RULE=83 N=X83 MODELS=/work/scratch/s71/models R=reports/training/s71_split SE=1 FB= AS=156 ANC=edit ALPHA=0.925 \
  EDIT_T=800 ETA=1 BDRAW=/work/scratch/s39/eval11/B_X83 STAGES=${STAGES:-"gate A C' B C+ T"} \
  bash reports/training/s66_reference/run73.sh
