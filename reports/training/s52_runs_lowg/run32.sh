# Rule 32's val runs (rule32.txt was committed before these ran). S=/work/scratch/s39; shipped weights J40m.
set -e
cd /work/main; . .venv/bin/activate
D=reports/training/s52_runs_lowg
PYWRAP=$D/dropped.py STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40m_se4_drop /work/scratch/s49/J40m_model 4
python $D/dropped.py reports/training/s50_anneal/float_probe.py -1.6,0,0 4,3,2 > $D/float_probe_drop.txt
