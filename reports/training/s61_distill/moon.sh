# The low-gravity screen (env_probe.py --moon 16, n 64 walk/run pairs) on the models whose stage C' is known.
set -u
cd /work/main; . .venv/bin/activate
P=reports/training/s60_wind/env_probe.py
python $P --walks 0 --moon 16 simdiff/assets/default_model /work/scratch/s55/J40m_sa_model /work/scratch/s57/X15sa_model \
  /work/scratch/s61/D3_model /work/scratch/s59/X15sg_model
python $P --walks 0 --moon 16 --env-guidance 5 /work/scratch/s57/X15sa_model
