# Session 56, a description after rules 51-54 (not judged): stage A on two more seeds (102 103) for the shipped model
# and J40m_sa, to see how much the gravity-size figure moves between draws.
cd /work/main; . .venv/bin/activate
export SIMDIFF_SCRATCH=/work/scratch/s39 STEPS=50
for pair in J40m:simdiff/assets/default_model J40m_sa:/work/scratch/s55/J40m_sa_model; do
  n=${pair%%:*}; m=${pair#*:}
  ASEEDS="102 103" FB=3 bash reports/training/s39_drift_gpu/check.sh A ${n}_se4_fb3_s102 $m 4
  python reports/training/s54_refit/stage_a_pass.py /work/scratch/s39/eval11/A_${n}_se4_fb3_s102
done
