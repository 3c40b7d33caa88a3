#!/usr/bin/env bash
set -u
while pgrep -f "size71.sh|screen71.sh|size71b.sh" >/dev/null; do sleep 10; done
cd /work/main/reports/training/s60_wind; . /work/main/.venv/bin/activate
for M in ${MODELS:-X81_ref_a1_se1 X81_ref_a05_se5}; do
nice -n 5 python env_probe.py /work/scratch/s71/$M --walks 8 --seed 7900 | tee -a /work/main/reports/training/s71_split/wind_screens.log
done
