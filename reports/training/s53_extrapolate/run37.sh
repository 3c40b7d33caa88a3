# Rule 37, stage B (session 53): X1.5 on val, after X1's run (run36b.sh) ends.
set -u
while pgrep -f run36b.sh > /dev/null; do sleep 10; done
S=/work/scratch/s39; M=/work/scratch/s53; C=/work/main/reports/training/s39_drift_gpu/check.sh
export STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3"
bash $C B X1.5 $M/wx1.5 4
