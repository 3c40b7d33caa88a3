# Rule 43 stage A at alpha 0.25: (s_e, fallback) = (8, 6), (10, 7.5), (12, 9) until one passes. usage: run43A.sh NAME MODEL
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
while pgrep -f "run4[23]B.sh" > /dev/null; do sleep 15; done
for p in 8:6 10:7.5 12:9; do
  se=${p%%:*}; fb=${p#*:}
  ALPHA=0.25 FB=$fb STEPS=50 bash reports/training/s39_drift_gpu/check.sh A $1_se${se}_fb${fb} $2 $se
  python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_$1_se${se}_fb${fb} && break
done
