# Session 40's commands, in order (scratch S=/work/scratch/s39 from session 39: corpus3, aug_weakg, aug_gen, eval;
# train_walk150.txt = walk_split.py's output copied into corpus3/)
S=/work/scratch/s39
python reports/training/s40_walk_wind/walk_split.py $S/corpus3 > $S/corpus3/train_walk150.txt
simdiff data augment --corpus $S/corpus3 --out $S/aug_wind --split train_walk150 --share-mirrors --conditions 4 \
  --factors wind_x wind_y --max-pose-d-l2 6.586 --workers 2          # 316 s
for leg in 20 40 60; do  # three 20-minute legs of one run; each leg's export is a candidate
  simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try --init simdiff/assets/default_model \
    --adapters-init simdiff/assets/default_model --out $S/cw --config configs/adapters_paired_gpu_finetune.json \
    --env-pairs 10 --env-pairs-drift 20 --seed 40 --batch-size 64 --save-every 100 --device cpu \
    --text-table .gpu/captions.safetensors --max-minutes 20 --loader-workers 1 --no-progress
  cp -r $S/cw/model $S/cw${leg}_model
done
for n in cw20 cw40 cw60; do bash reports/training/s39_drift_gpu/check.sh A $n $S/${n}_model; done
bash reports/training/s39_drift_gpu/check.sh B cw20 $S/cw20_model
bash reports/training/s39_drift_gpu/stageC.sh cw20 $S/cw20_model   # guard.py at g -1.6 and at w_x +10 N
bash reports/training/s39_drift_gpu/check.sh T cw20 $S/cw20_model
