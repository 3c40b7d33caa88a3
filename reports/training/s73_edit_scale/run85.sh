#!/usr/bin/env bash
# Rule 85 (rule85.txt): X85 (X84's rebuilt weights, X83's sampling at the s_e choice85.txt names) through rule 73's stages
# (../s66_reference/run73.sh) with rule 84's gate (gate84.py, speed bar 0.209); stage-A seeds 160 161; lines in
# rule85_stages.txt. Stage B drawn anew (BDRAW). Makes /work/scratch/s73/models/X85_model from the chosen screen folder.
set -u
cd /work/main; R=reports/training/s73_edit_scale
SE=$(sed -n 's/^choice: s_e \([0-9.]*\) .*/\1/p' $R/choice85.txt)
[ -n "$SE" ] || { echo "rule 85: no s_e chosen, no draws"; exit 0; }
mkdir -p /work/scratch/s73/models; [ -d /work/scratch/s73/models/X85_model ] || cp -r /work/scratch/s73/X85_se$SE /work/scratch/s73/models/X85_model
RULE=85 N=X85 MODELS=/work/scratch/s73/models R=$R SE=$SE FB= AS=160 ANC=edit ALPHA=0.925 \
  EDIT_T=800 ETA=1 BDRAW=/work/scratch/s39/eval11/B_X85 GATE=reports/training/s72_lowloc/gate84.py \
  GATE_ARGS=0.209 STAGES=${STAGES:-"gate A C' B C+ T"} bash reports/training/s66_reference/run73.sh
