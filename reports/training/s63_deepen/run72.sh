# Rule 72 (session 63): G63 at s_e 3 / fallback 2 (/work/scratch/s63/G63s3_model: G63's weights, sampling.json changed
# as rule72.txt says), the gate probe, then run68.sh's stages with cprime4.sh at SE 3 / FB 2, stage-A seeds 138 139;
# stage B scores G63's Earth draw (B_G63, drawn by stageB.sh; Earth without fallback does not depend on s_e).
set -u
cd /work/main; . .venv/bin/activate
PROBE=/work/scratch/s63_G63s3_probe.log
[ -s $PROBE ] || python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 /work/scratch/s63/G63s3_model > $PROBE 2>&1
NAME=G63s3 RULE=72 AS=138 SE=3 FB=2 B_NAME=G63 O=/work/scratch/s63 R=reports/training/s63_deepen PROBE=$PROBE \
  CPRIME="bash reports/training/s63_deepen/cprime4.sh" bash reports/training/s61_distill/run68.sh
