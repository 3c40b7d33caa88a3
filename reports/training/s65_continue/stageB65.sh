# Session 65 (descriptive, no rule): evaluator 1 rebuilt (s55_reference recipe), then val stage B for G63 at alpha 0
# (backbone alone at Earth) and at its shipped alpha 0.5, same draws (seeds 0 1, n 128), evaluator 1 only.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
[ -f $S/eval/model.safetensors ] || nice -n 5 simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval --epochs 4 --no-progress
echo "[$(date -u +%H:%M)] evaluator done"
M=/work/main/reports/training/s63_deepen/G63_model
export STEPS=50
ALPHA=0 bash reports/training/s39_drift_gpu/check.sh B G63a0_s65 $M 4
echo "[$(date -u +%H:%M)] a0 done"
ALPHA=0.5 bash reports/training/s39_drift_gpu/check.sh B G63a05_s65 $M 4
echo "[$(date -u +%H:%M)] a05 done"
