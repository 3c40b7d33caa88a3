# Session 57, described after rule 57's verdict (not judged; for the next session's rule): X15sa at s_e 5 (fallback 3)
# -- does a stronger environment guidance lift the apex size clear of 0.5, and what does it cost the val captions under
# g -1.6? Stage A on seeds 104-107 and C' on seeds 1 2 (s_e 5 without fallback).
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; R=reports/training/s57_pooled_a; M=/work/scratch/s57/X15sa_model
export SIMDIFF_SCRATCH=$S STEPS=50
ASEEDS="104 105 106 107" FB=3 bash reports/training/s39_drift_gpu/check.sh A X15sa_se5_fb3_s104 $M 5
python $R/stage_a55.py $S/eval11/A_X15sa_se5_fb3_s104 | tee -a $R/described_X15sa.txt
SEEDS="1 2" python reports/training/s37_env_guidance/guard.py -1.6,0,0 5 $S/eval11/C12_X15sa_se5/-1.6,0,0 $M
python reports/training/s56_source_anchored/c51.py C12 X15sa_se5 | tee -a $R/described_X15sa.txt
