# Session 57, described (not judged): X15sa (s_e 4, fallback 3) on a stage A twice as large -- 32 samples per jump
# prompt over val seeds 108 109 (n 192 jump pairs) -- to see whether its apex size of 0.495 sits at the bar or under it.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; R=reports/training/s57_pooled_a
export SIMDIFF_SCRATCH=$S STEPS=50
JS=32 ASEEDS="108 109" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sa_se4_fb3_js32_s108 /work/scratch/s57/X15sa_model 4
python $R/stage_a55.py $S/eval11/A_X15sa_se4_fb3_js32_s108 | tee -a $R/described_X15sa.txt
