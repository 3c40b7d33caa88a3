# session 43 rule 17: adapters of BASE fine-tuned 15 min on weak36, probe, stages A, B, C.
# usage: bash chain.sh BASE_MODEL   (the model shipped after rule 15; its backbone is frozen, its adapters the start)
cd /work/main && . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s43; B=$1
mkdir -p $O
simdiff train adapters --data $S/aug_weakg $S/aug_gen $S/aug_wind --split weak36 --init $B \
  --adapters-init $B --out $O/ad --config configs/adapters_paired_gpu_finetune.json \
  --env-pairs 10 --env-pairs-drift 20 --seed 43 --batch-size 64 --save-every 100 --device cpu \
  --text-table .gpu/captions.safetensors --max-minutes 15 --loader-workers 1 --no-progress
test -f $O/ad/model/model.safetensors || { echo "no adapter export"; exit 1; }
cp -r $O/ad/model $O/G17_model
python reports/training/s41_jump_backbone/jump_probe.py $O/G17_model '[{}]' 8
bash reports/training/s39_drift_gpu/check.sh A G17 $O/G17_model
bash reports/training/s39_drift_gpu/check.sh B G17 $O/G17_model
bash reports/training/s39_drift_gpu/stageC.sh G17 $O/G17_model
echo chain done
