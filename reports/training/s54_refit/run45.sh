# Rule 45 (exploratory): X15a's adapter run resumed to STEPS steps (default 3,000; session 54 ran STEPS=2000 for time:
# on a run whose checkpoint is already at STEPS it only writes the model), then stage A (s_e 4, fb 3) and stage C at
# g -1.6 (s_e 4). Model and report folders are named X15a<STEPS/1000>k.
set -e
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; W=/work/scratch/s53; M=$W/wx1.5; O=/work/scratch/s54
STEPS=${STEPS:-3000}; N=X15a$((STEPS / 1000))k
[ -d $O/ad45 ] || cp -r $O/ad42 $O/ad45
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
  --init $M --adapters-init $M --out $O/ad45 --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 53 --batch-size 64 --save-every 100 --device cpu --steps $STEPS \
  --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress
rm -rf $O/${N}_model; cp -r $O/ad45/model $O/${N}_model; cp $M/sampling.json $O/${N}_model/
FB=3 STEPS=50 bash reports/training/s39_drift_gpu/check.sh A ${N}_se4_fb3 $O/${N}_model 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_${N}_se4_fb3 || true
export SIMDIFF_SCRATCH=$S STEPS=50
python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 $S/eval11/C_${N}_se4/-1.6,0,0 $O/${N}_model
