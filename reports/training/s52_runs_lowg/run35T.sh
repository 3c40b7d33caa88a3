# Rule 35's test run (after its stage A passed), with the package's plumbed option (FB): s_e 4, fallback 3, cleanup 3.
# The Earth sections' parts are copied from rule 33's test run (same motions at any s_e); the response is measured.
set -e
cd /work/main
S=/work/scratch/s39
mkdir -p $S/eval11/T_3_J40m_se4_fb3/parts
cp $S/eval11/T_3_J40m_se3_drop/parts/{test_split,jumps,speeds}.json $S/eval11/T_3_J40m_se4_fb3/parts/
FB=3 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m_se4_fb3 /work/scratch/s49/J40m_model 4
