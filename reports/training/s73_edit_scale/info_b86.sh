#!/usr/bin/env bash
# Session 73, information after rule 86 ended at C' (no rule): X86's stage B (Earth, val n 128 x seeds 0 1, drawn anew,
# with the walk guard) by run73.sh's own stage, so a later rule can tell whether X86's Earth samples pass on val.
# Lines in rule86info_stages.txt.
cd /work/main
RULE=86info N=X86 MODELS=/work/scratch/s73/models R=reports/training/s73_edit_scale SE=1 FB= AS=160 ANC=edit ALPHA=0.925 \
  EDIT_T=900 ETA=1 BDRAW=/work/scratch/s39/eval11/B_X86 STAGES=B bash reports/training/s66_reference/run73.sh
