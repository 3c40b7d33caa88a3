# Session 66: G63r's gravity answer with the adapters' strength alpha 1.0 in the reference anchor's answer to phi
# (Earth unchanged: anchor_alpha 0), s_e 3 and 4, the same fresh probe seeds 7500+ as se_screen.sh.
cd /work/main; . .venv/bin/activate
for se in 3 4; do
  python reports/training/s60_wind/env_probe.py --walks 0 --jumps 8 --seed 7500 --env-guidance $se /work/scratch/s66/G63r_a1.0_model
done
