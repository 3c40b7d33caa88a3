# Session 46: the commands as run (S=/work/scratch/s39 holds session 45's rebuilt corpus3 and evaluator; J40 =
# /work/scratch/s41/J40_model, a copy of simdiff/assets/default_model's weights). One job at a time on 2 cores.
S=/work/scratch/s39
M=/work/scratch/s41/J40_model
# screens (outside the val/test protocol; run from /work/scratch)
python reports/training/s41_jump_backbone/jump_probe.py $M '[{"length":60},{"length":80},{"length":120}]' 8
python reports/training/s46_length/speed_probe.py $M 40,60,80,120 8
# rule 19, stage B (val Earth n 128 seeds 0 1); the baseline (2.5, 20) is session 45's eval11/B_J40
for ws in 3.5,20 5.0,20 2.5,50 3.5,50 5.0,50; do
  w=${ws%,*}; s=${ws#*,}
  W=$w STEPS=$s bash reports/training/s39_drift_gpu/check.sh B J40w${w}s${s} $M
done
python reports/training/s46_length/rule19_table.py $S/eval11/B_J40 $S/eval11/B_J40w{3.5s20,5.0s20,2.5s50,3.5s50,5.0s50}
# the first in order, stages C and A
W=2.5 STEPS=50 bash reports/training/s39_drift_gpu/stageC.sh J40w2.5s50 $M
W=2.5 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40w2.5s50 $M
python reports/training/s39_drift_gpu/summarize.py $S/eval11/A_J40w2.5s50 "$S/eval11/C_J40w2.5s50/-1.6,0,0" "$S/eval11/C_J40w2.5s50/-9.81,10,0"
# adopted: the test split on it, and J40 at (2.5, 20) with the same evaluator
W=2.5 STEPS=50 bash reports/training/s39_drift_gpu/check.sh T J40w2.5s50 $M
bash reports/training/s39_drift_gpu/check.sh Tq J40 $M
# rule 20: stage C at g -1.6 for s_e 3, then 2.5 (each failed its R@3 guard; stage A and +10 N not needed)
export SIMDIFF_SCRATCH=$S
for se in 3 2.5; do
  W=2.5 STEPS=50 python reports/training/s37_env_guidance/guard.py -1.6,0,0 $se "$S/eval11/C_J40s50se$se/-1.6,0,0" $M
done
W=2.5 STEPS=100 bash reports/training/s39_drift_gpu/check.sh B J40w2.5s100 $M   # screen after rule 20, not judged by a rule
