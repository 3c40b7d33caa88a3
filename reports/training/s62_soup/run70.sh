# Rule 70 (session 62): rule 68's gate and stages for the soup that rule 70 names (stage-A seeds 134 135).
# The soups and their probes: bash soups.sh (logs /work/scratch/s62_S<b>.log). Usage: bash run70.sh S<b>
NAME=$1 RULE=70 AS=134 O=/work/scratch/s62 R=reports/training/s62_soup PROBE=/work/scratch/s62_$1.log \
  bash "$(dirname "$0")/../s61_distill/run68.sh"
