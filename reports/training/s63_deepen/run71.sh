# Rule 71 (session 63): the gate probe, then rule 68's stages (run68.sh) with rule 71's C' (cprime4.sh) and stage-A seeds
# 136 137, for G63 (/work/scratch/s63/G63_model). Stages already judged are not redrawn (their samples are scored again).
set -u
cd /work/main; . .venv/bin/activate
PROBE=/work/scratch/s63_G63_probe.log
[ -s $PROBE ] || python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 /work/scratch/s63/G63_model > $PROBE 2>&1
NAME=G63 RULE=71 AS=136 O=/work/scratch/s63 R=reports/training/s63_deepen PROBE=$PROBE \
  CPRIME="bash reports/training/s63_deepen/cprime4.sh" bash reports/training/s61_distill/run68.sh
