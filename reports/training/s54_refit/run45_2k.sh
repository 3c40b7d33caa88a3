# Rule 45 (exploratory): X15a's adapter run stopped at 2,000 steps (session 54, for time), then stage A (s_e 4, fb 3) and stage C at g -1.6 (s_e 4).
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s53; M=$W/wx1.5; O=/work/scratch/s54
[ -d $O/ad45 ] || cp -r $O/ad42 $O/ad45
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
  --init $M --adapters-init $M --out $O/ad45 --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 53 --batch-size 64 --save-every 100 --device cpu --steps 2000 \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress
rm -rf $O/X15a2k_model; cp -r $O/ad45/model $O/X15a2k_model; cp $M/sampling.json $O/X15a2k_model/
FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A X15a2k_se4_fb3 $O/X15a2k_model 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_X15a2k_se4_fb3 || true
export SIMDIFF_SCRATCH=$S STEPS=50
python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 $S/eval11/C_X15a2k_se4/-1.6,0,0 $O/X15a2k_model
