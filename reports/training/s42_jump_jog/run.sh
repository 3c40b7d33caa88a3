# Session 42's commands, in order (scratch S=/work/scratch/s39 from sessions 39-41; the shipped model J40 kept as
# /work/scratch/s41/J40_model, its stage runs in $S/eval11/{A,B,T}_J40 and C_J40)
S=/work/scratch/s39
python reports/training/s42_jump_jog/mix_split.py $S/corpus3 8 8 3 > $S/corpus3/train_mix.txt   # rule 15's split
STEPS=4000 MINUTES=55 bash reports/training/s42_jump_jog/chain.sh   # rule 15: first backbone leg (stopped by hand after ~15 min)
STEPS=1600 MINUTES=90 bash reports/training/s42_jump_jog/chain.sh   # resumes to step 1,600 (stopped at step 800: rule15_outcome.txt)
for se in 5 4 3; do                                # rule 16 stage A: Earth parts of A_J40 reused
  cp -r $S/eval11/A_J40 $S/eval11/A_J40se$se
  bash reports/training/s39_drift_gpu/check.sh A J40se$se /work/scratch/s41/J40_model $se
done
bash reports/training/s39_drift_gpu/stageC.sh J40se5 /work/scratch/s41/J40_model 5   # g -1.6 only: failed (c)
bash reports/training/s39_drift_gpu/stageC.sh J40se4 /work/scratch/s41/J40_model 4   # g -1.6 only: failed (c)
bash reports/training/s39_drift_gpu/stageC.sh J40se3 /work/scratch/s41/J40_model 3   # both phi: failed (c) at g -1.6
python reports/training/s39_drift_gpu/summarize.py $S/eval11/A_J40se3 $S/eval11/A_J40se4 $S/eval11/A_J40se5
