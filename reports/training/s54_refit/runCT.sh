# Rules 42/43 stages C and T for the chosen candidate. usage: runCT.sh NAME MODEL S_E FALLBACK ALPHA
# C: g -1.6 and w_x +10 N on val n 128 seed 0 at s_e without fallback (rule 38); T: test n 256 x seeds 0-4, response on.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
while pgrep -f "run4[23][AB].sh" > /dev/null; do sleep 15; done
STEPS=50 ALPHA=$5 bash reports/training/s39_drift_gpu/stageC.sh $1 $2 $3
ALPHA=$5 FB=$4 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T $1 $2 $3
