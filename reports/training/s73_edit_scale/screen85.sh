#!/usr/bin/env bash
# Rule 85's choice of s_e (rule85.txt): screen_grid.sh at edit_t 800, s_e in SES (default 1 1.25 1.5 2) -> choice85.txt.
EDITS=800 SES=${SES:-"1 1.25 1.5 2"} NAMEFMT='X85_se$SE' CHOICE=choice85.txt SELECT_ARGS="--only /work/scratch/s73/X85_" \
  bash /work/main/reports/training/s73_edit_scale/screen_grid.sh
