# Session 55's commands, in order (fresh machine: the scratch S=/work/scratch/s39 was rebuilt; venv as the README says).
S=/work/scratch/s39
cp -r simdiff/assets/default_model /work/scratch/s49/J40m_model                                       # J40m, the shipped weights
simdiff data build --shared ../shared/data --out $S/corpus3 --workers 2 --quiet                       # 146 s, 8,070 clips
cp reports/training/s29_weak_gravity/train_flight_split.txt $S/corpus3/train_flight.txt
cp reports/training/s29_weak_gravity/train_sub300_split.txt $S/corpus3/train_sub300.txt
python reports/training/s40_walk_wind/walk_split.py $S/corpus3 > $S/corpus3/train_walk150.txt
python reports/training/s42_jump_jog/mix_split.py $S/corpus3 8 16 1 > $S/corpus3/train_jumpy.txt
simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval --epochs 4 --no-progress             # 4.7 min each
simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval2 --epochs 4 --seed 1 --no-progress
simdiff evaluate train-evaluator --corpus $S/corpus3 --out $S/eval3 --epochs 4 --seed 2 --no-progress
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_c3 /work/scratch/s49/J40m_model 4
bash reports/training/s55_reference/run48.sh      # rule 48 (repro.py first)
bash reports/training/s55_reference/run49.sh      # rule 49
# measurement M1 (sim_r3_plan.txt): 5.4 min of simulation, then seconds of scoring
simdiff data augment --corpus $S/corpus3 --out $S/aug_val16 --mode paired --conditions 1 --factors gravity \
  --gravity-range -1.6 -1.599 --split val --share-mirrors --max-pose-d-l2 6.586 --workers 2 --seed 0 --no-progress
python reports/training/s55_reference/sim_r3.py $S/aug_val16 $S/corpus3 $S/eval $S/eval2 $S/eval3          # m1_result.txt
LONG=1 python reports/training/s55_reference/sim_r3.py $S/aug_val16 $S/corpus3 $S/eval $S/eval2 $S/eval3   # m1_result_long.txt
