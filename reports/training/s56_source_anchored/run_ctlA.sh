# Session 56, a description after rule 53 (not judged): stage A of the matched control (plain targets), to tell
# whether the small apex answer comes with the anchoring or with the extra 1,000 fine-tuning steps.
cd /work/main; . .venv/bin/activate
export SIMDIFF_SCRATCH=/work/scratch/s39 STEPS=50
FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_ctl_se4_fb3 /work/scratch/s55/J40m_ctl_model 4
python reports/training/s54_refit/stage_a_pass.py /work/scratch/s39/eval11/A_J40m_ctl_se4_fb3
