# Rule 36, stage B (session 53): the shipped model (same code) and X2, X3, X1 on val; then the table.
set -u
S=/work/scratch/s39; M=/work/scratch/s53; C=/work/main/reports/training/s39_drift_gpu/check.sh
export STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3"
bash $C B J40m_c3 /work/main/simdiff/assets/default_model 4
for l in 2 3 1; do bash $C B X$l $M/wx$l 4; done
