# Session 54 (exploratory, before rule 42's stages): adapters re-fitted on X1.5's backbone (X1.5a), rule 40's recipe.
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s53; M=$W/wx1.5; O=/work/scratch/s54
mkdir -p $O
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
  --init $M --adapters-init $M --out $O/ad42 --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 53 --batch-size 64 --save-every 100 --device cpu --steps 1000 \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress
rm -rf $O/X15a_model; cp -r $O/ad42/model $O/X15a_model; cp $M/sampling.json $O/X15a_model/
echo TRAIN_DONE
