# Rule 42 stage A: X15a (then X1aB with the backbone anchor if it passed stage B) at s_e 4, 5, 6 until one passes.
# usage: run42A.sh NAME MODEL ANCHOR
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
while pgrep -f run42B.sh > /dev/null; do sleep 15; done
for se in 4 5 6; do
  ANCHOR=$3 FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A $1_se${se}_fb3 $2 $se
  python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_$1_se${se}_fb3 && break
done
