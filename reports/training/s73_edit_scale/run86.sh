#!/usr/bin/env bash
# Rule 86 (rule86.txt): X86 (X84's rebuilt weights, X83's sampling at the (edit_t, s_e) choice86.txt names) through rule
# 73's stages (../s66_reference/run73.sh) with rule 84's gate (gate84.py, speed bar 0.209); stage-A seeds 160 161; lines
# in rule86_stages.txt. Stage B drawn anew (BDRAW). Makes /work/scratch/s73/models/X86_model from the chosen folder.
set -u
cd /work/main; R=reports/training/s73_edit_scale
F=$(sed -n 's/^choice: \(\/[^ ]*\) .*/\1/p' $R/choice86.txt)
[ -n "$F" ] || { echo "rule 86: nothing chosen, no draws"; exit 0; }
SE=$(python -c "import json; print(json.load(open('$F/sampling.json'))['env_guidance'])")
ET=$(python -c "import json; print(json.load(open('$F/sampling.json'))['edit_t'])")
mkdir -p /work/scratch/s73/models; [ -d /work/scratch/s73/models/X86_model ] || cp -r $F /work/scratch/s73/models/X86_model
RULE=86 N=X86 MODELS=/work/scratch/s73/models R=$R SE=$SE FB= AS=160 ANC=edit ALPHA=0.925 \
  EDIT_T=$ET ETA=1 BDRAW=/work/scratch/s39/eval11/B_X86 GATE=reports/training/s72_lowloc/gate84.py \
  GATE_ARGS=0.209 STAGES=${STAGES:-"gate A C' B C+ T"} bash reports/training/s66_reference/run73.sh
