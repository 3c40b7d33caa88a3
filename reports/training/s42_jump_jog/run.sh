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

# Session 44 (fresh machine, 2 cores, no GPU): the scratch was gone, so sessions 29/39/40's data were rebuilt with
# their commands (same seeds; the counts match the earlier reports: 8,070 clips; aug_gen 2,812/4,200 kept at the
# calibrated pose bound 6.586; aug_weakg 1,222/7,776; aug_wind 870/1,500; evaluator val top-1 0.261 / top-3 0.587).
S=/work/scratch/s39
simdiff data build --shared ../shared/data --out $S/corpus3 --workers 2 --quiet                       # 139 s
simdiff train text-table $S/corpus3 --out .gpu/captions.safetensors                                   # 14 s
cp reports/training/s29_weak_gravity/train_flight_split.txt $S/corpus3/train_flight.txt
cp reports/training/s29_weak_gravity/train_sub300_split.txt $S/corpus3/train_sub300.txt
python reports/training/s40_walk_wind/walk_split.py $S/corpus3 > $S/corpus3/train_walk150.txt
python reports/training/s42_jump_jog/mix_split.py $S/corpus3 8 8 3 > $S/corpus3/train_mix.txt
simdiff data augment --corpus $S/corpus3 --out $S/aug_gen --split train_sub300 --share-mirrors --conditions 6 \
  --workers 2 --seed 0 --no-progress                                                                  # 13 min
simdiff data augment --corpus $S/corpus3 --out $S/aug_weakg --split train_flight --share-mirrors --conditions 8 \
  --factors gravity --gravity-range -5 -1 --no-retime --max-pose-d-l2 6.586 --workers 2 --seed 0 --no-progress  # 15 min
simdiff data augment --corpus $S/corpus3 --out $S/aug_wind --split train_walk150 --share-mirrors --conditions 4 \
  --factors wind_x wind_y --max-pose-d-l2 6.586 --workers 2 --no-progress                            # 5 min
simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval --epochs 4 --no-progress           # 4.4 min
cp -r simdiff/assets/default_model /work/scratch/s41/J40_model
STEPS=1600 MINUTES=90 bash reports/training/s42_jump_jog/chain.sh       # rule 15, K55 trained anew (amendment of 14:40)
bash reports/training/s39_drift_gpu/check.sh B J40 /work/scratch/s41/J40_model   # J40's baselines, this evaluator
bash reports/training/s39_drift_gpu/stageC.sh J40 /work/scratch/s41/J40_model

# Session 45 (fresh machine again; session 44 was cut off after the backbone leg): the same commands, in one script,
# one job at a time: the session-44 block above up to the evaluator, J40's baselines, then the chain.
#   (as the session-44 block above, corpus to evaluator; then)
bash reports/training/s39_drift_gpu/check.sh B J40 /work/scratch/s41/J40_model   # -> stageB/J40_s45
bash reports/training/s39_drift_gpu/stageC.sh J40 /work/scratch/s41/J40_model    # -> stageC/J40_s45
STEPS=1600 MINUTES=90 bash reports/training/s42_jump_jog/chain.sh                # K55: not adopted (rule15_outcome.txt)
# rule 17 (base J40) and its control: ../s43_weak_pairs/run.sh
# rule 18: ../s45_gravity_confirm/run.sh (stage A on fresh seeds 200 201 for K55 and J40)
