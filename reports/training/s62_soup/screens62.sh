# J62's screens (j62_plan.txt), in order; appends to screens.txt beside this script.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s62_soup; M=/work/scratch/s62/J62_model; S=/work/scratch/s39
(cd reports/training/s53_extrapolate && python ag_probe.py $M $M '[{"lam": 0}]' 8 | sed "s|^|J62 |") >> $R/screens.txt
(cd reports/training/s53_extrapolate && python nonjump_probe.py $M && python walk_probe.py $M) >> $R/screens.txt
python $R/retention.py $M /work/scratch/s57/X15sa_model >> $R/screens.txt
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J62 $M 4
