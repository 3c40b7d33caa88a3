#!/usr/bin/env bash
# Session 69: early-boost screens on G63r5 (rule 74's weights and settings), probe seeds 7700+ (ballistic_screen.py).
cd /work/main/reports/training/s69_bigjumps; . /work/main/.venv/bin/activate
for c in ${CONFIGS:-900:10 900:20}; do
  T=${c%%:*} S=${c#*:}
  L=$(nice -n 5 python early_screen.py /work/scratch/s66/G63r5_model --t-early $T --se-early $S \
      --dump /work/scratch/s69/dump_early_${T}_$S.json | tail -1)
  echo "{\"t_early\": $T, \"se_early\": $S, \"screen\": $L}" | tee -a screens.log
done
