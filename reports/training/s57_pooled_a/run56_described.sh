# Session 57, described after rule 56's verdict (not judged): X15sa at Earth (stage B + walk guard) and stage A on
# seeds 104-107, so the next session knows whether source-anchored adapters keep the jumping backbone's jumps and
# its gravity answer.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; R=reports/training/s57_pooled_a; M=/work/scratch/s57/X15sa_model
export SIMDIFF_SCRATCH=$S STEPS=50
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B X15sa $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee -a /work/scratch/s57/walk56.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R/b56.py X15sa $W | tee -a $R/described_X15sa.txt
(cd reports/training/s53_extrapolate && python stage_b.py J40m_c3 X15sa) | tee -a $R/described_X15sa.txt
ASEEDS="104 105 106 107" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sa_se4_fb3_s104 $M 4
python $R/stage_a55.py $S/eval11/A_X15sa_se4_fb3_s104 | tee -a $R/described_X15sa.txt
