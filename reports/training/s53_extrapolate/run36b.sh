# Rule 36, stage B after the amendment (session 53): X2 fails the walk guard (4 of 64 walks jump), X3 withdrawn; X1 only.
set -u
S=/work/scratch/s39; M=/work/scratch/s53; C=/work/main/reports/training/s39_drift_gpu/check.sh
export STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3"
bash $C B X1 $M/wx1 4
