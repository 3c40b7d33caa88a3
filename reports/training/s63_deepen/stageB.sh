# Stage B of rule 68 (val, Earth, evaluators 1-3, then the walk guard; verdict b56.py) for G63, run after rule 71's C'
# failed: descriptive under rule 71 (it decides nothing there). Earth samples do not depend on the environment
# guidance, so a later rule on these weights and the shipped sampling.json scores the same samples again.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; M=/work/scratch/s63/G63_model; R=reports/training/s63_deepen
export SIMDIFF_SCRATCH=$S STEPS=50
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B G63 $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a /work/scratch/s63/walk71.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python reports/training/s57_pooled_a/b56.py G63 $W | sed 's/^/stage B (descriptive, after C'"'"' failed): /' | tee -a $R/rule71_stages.txt
