#!/usr/bin/env bash
# Rule 78's choice of s_e (rule78.txt): ballistic_screen.py on G63r5 (G63's weights, rule 74's sampling.json) at
# s_e 5, 6, 7, seeds 7700+, the package's ballistic at bdb7c4d; one JSON line each in screens.log.
set -u
cd /work/main/reports/training/s67_ballistic; . /work/main/.venv/bin/activate
for se in ${SES:-5 6 7}; do
  python ballistic_screen.py /work/scratch/s66/G63r5_model --env-guidance $se --dump /work/scratch/s68/dump78_se$se.json \
    | tee -a ../s68_lowg_gpu/screens.log
done
