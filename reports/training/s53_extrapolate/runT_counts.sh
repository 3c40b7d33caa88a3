# Session 53: the shipped model's test run again with the model check's new counts (walk/run samples that jump;
# samples re-sampled at the fallback s_e). The test-split and jump parts are reused (fingerprints unchanged; same
# motions, same model folder as that run: the model stamp holds its path); speeds and the response sections are
# measured again (their fingerprints changed).
set -e
cd /work/main
S=/work/scratch/s39
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53/parts
cp $S/eval11/T_3_J40m_se4_fb3/parts/{test_split,jumps}.json $S/eval11/T_3_J40m_se4_fb3_c53/parts/
FB=3 STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m_se4_fb3_c53 /work/scratch/s49/J40m_model 4
. .venv/bin/activate && python reports/training/s52_runs_lowg/test_summary.py T_3_J40m_se4_fb3_c53 T_3_J40m_se4_fb3
