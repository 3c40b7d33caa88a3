# Session 66, after rule 73's gate failed on the apex change (0.247 m at s_e 3, bar 0.32): G63r's gravity answer at
# s_e 4, 5 and 6 on fresh probe seeds (7500+; the gate's are 7000+), jump prompts only (8 samples each, Earth vs g -1.6).
cd /work/main; . .venv/bin/activate
for se in 4 5 6; do
  python reports/training/s60_wind/env_probe.py --walks 0 --jumps 8 --seed 7500 --env-guidance $se /work/scratch/s66/G63r_model
done
