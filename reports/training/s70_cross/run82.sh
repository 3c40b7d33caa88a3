#!/usr/bin/env bash
# Rule 82 (rule82.txt): X82 (X81's 600-step weights; edit anchor, edit t 800, alpha 1, DDIM eta 1, s_e 1, no fallback)
# through rule 73's stages (../s66_reference/run73.sh), stage-A seeds 156 157; verdict lines in rule82_stages.txt.
# Needs /work/scratch/s70/X82_model (snap_600 + the sampling.json of rule82.txt). STAGES default "gate A C' B C+ T";
# stage B is drawn anew (BDRAW), since eta 1 changes the Earth samples.
cd /work/main
RULE=82 N=X82 MODELS=/work/scratch/s70 R=reports/training/s70_cross SE=1 FB= AS=156 ANC=edit ALPHA=1 EDIT_T=800 ETA=1 \
  BDRAW=/work/scratch/s39/eval11/B_X82 STAGES=${STAGES:-"gate A C' B C+ T"} bash reports/training/s66_reference/run73.sh
