# Rule 70's candidates: S(b) = (1 - b) D4 + b D5 for b in 0.4 0.5 0.6 0.7 (soup.py, session 60), each probed with
# env_probe.py --walks 8 --jumps 8 --moon 16 (seeds 7000+). One log per soup: /work/scratch/s62_S<b>.log
set -u
cd /work/main; . .venv/bin/activate
O=/work/scratch/s62; mkdir -p $O
for B in ${BS:-0.7 0.6 0.5 0.4}; do
  N=S$(echo $B | tr -d .); M=$O/${N}_model
  python reports/training/s60_wind/soup.py /work/scratch/s61/D4_model /work/scratch/s61/D5_model $B $M || exit 1
  python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 $M > /work/scratch/s62_$N.log 2>&1
  tail -1 /work/scratch/s62_$N.log
done
