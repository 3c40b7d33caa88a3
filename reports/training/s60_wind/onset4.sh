set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s60
python -m simdiff train adapters --targets source-anchored --twin-frames overlap --pair-twins wind \
    --drift-pairs wind --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
    --init /work/scratch/s57/wx1.5 --adapters-init /work/scratch/s57/X15sa_model --out $O/adON4 \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 63 --batch-size 64 \
    --ema-decay 0.99 --save-every 100 --device cpu --steps 300 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress || exit 1
M=$O/ONgx300_model; rm -rf $M; cp -r $O/adON4/model $M; cp /work/scratch/s57/X15sa_model/sampling.json $M/
python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 $M
