# Rule 40 (session 53, exploratory): adapters re-fitted on X1's backbone, then stage A.
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s53; M=$W/wx1
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
  --init $M --adapters-init $M --out $W/ad40 --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 53 --batch-size 64 --save-every 100 --device cpu --steps 1000 \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress
rm -rf $W/X1a_model; cp -r $W/ad40/model $W/X1a_model; cp $M/sampling.json $W/X1a_model/
FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X1a_se4_fb3 $W/X1a_model 4
python reports/training/s52_runs_lowg/stage_a.py $S/eval11/A_J40m_se4_fb3 $S/eval11/A_X1_se4_fb3 $S/eval11/A_X1a_se4_fb3
