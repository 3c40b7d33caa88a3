# Session 52's commands (scratch S=/work/scratch/s39 from sessions 39-51; the low-gravity run set from session 51).
# Rule 31 (rule31.txt) was written and committed before these ran.
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s52; M=/work/scratch/s49/J40m_model
mkdir -p $W
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind /work/scratch/s51_aug_runs_lowg --split first_try \
  --init $M --adapters-init $M --out $W/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 52 --batch-size 64 --save-every 100 --device cpu --steps 1000 \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress
rm -rf $W/J52_model; cp -r $W/ad/model $W/J52_model; cp $M/sampling.json $W/J52_model/
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J52_se3 $W/J52_model 3
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J52_se4 $W/J52_model 4
