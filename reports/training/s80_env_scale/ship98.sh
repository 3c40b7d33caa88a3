#!/usr/bin/env bash
# Rule 98's ship step (rule98.txt), run only when v94.py test says SHIP for T_X98: X96's weights with rule 98's sampling
# (edit t 950, s_e 1.1) become the default model, through session 79's ship step.
N=X98 R=reports/training/s80_env_scale X=/work/scratch/s80/models/X98 exec bash /work/main/reports/training/s79_refit/ship96.sh
