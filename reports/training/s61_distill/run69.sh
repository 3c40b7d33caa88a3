# Rule 69 (session 61): rule 68's gate and stages for D6 (stage-A seeds 132 133). D6 is trained and probed by:
# NAME=D6 INIT=/work/scratch/s61/D4_model FT=/work/scratch/s59/X15sg_model MINF=0.2 bash run_d4.sh > /work/scratch/s61_d6.log
RULE=69 NAME=D6 AS=132 bash "$(dirname "$0")/run68.sh"
