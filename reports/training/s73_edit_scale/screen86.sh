#!/usr/bin/env bash
# Rule 86's choice of (edit_t, s_e) (rule86.txt): screen_grid.sh at edit_t in EDITS (default 900 950) x s_e in SES
# (default 1 1.25) -> choice86.txt.
EDITS=${EDITS:-"900 950"} SES=${SES:-"1 1.25"} NAMEFMT='X86_t${ET}_se$SE' CHOICE=choice86.txt \
  SELECT_ARGS="--prefix /work/scratch/s73/X86_" bash /work/main/reports/training/s73_edit_scale/screen_grid.sh
