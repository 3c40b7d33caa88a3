#!/usr/bin/env bash
# Session 67: G63's adapters continued on CPU with the low-gravity replays added (aug_lowg, aug_lowg.sh), session 64's
# recipe otherwise (cont.sh: batch 64, lr 1e-4 constant, lambda 10, mu 20, EMA 0.999; seed 67), snapshots every 600
# steps exported and screened (ballistic_screen.py, probe seeds 7700+) with rule 74's sampling.json (reference anchor, anchor_alpha 0, s_e 5, fallback 4).
set -u
cd /work/scratch/s67; . /work/main/.venv/bin/activate
[ -f aug_lowg/adapt.txt ] || cp aug_lowg/first_try.txt aug_lowg/adapt.txt
for d in aug_weakg aug_gen aug_wind; do [ -e $d ] || ln -s /work/scratch/s64/$d $d; done
M=/work/main/reports/training/s63_deepen/G63_model
for S in ${SNAPS:-600 1200}; do
  nice -n 5 python -m simdiff train adapters --data aug_weakg aug_gen aug_wind aug_lowg --split adapt --init $M \
    --adapters-init $M --out ad67 --config /work/main/reports/training/s67_ballistic/ad67_config.json --steps $S \
    --env-pairs 10 --env-pairs-drift 20 --text-table /work/main/.gpu/captions.safetensors --no-progress \
    --loader-workers 1 || exit 1
  rm -rf snap_$S; cp -r ad67/model snap_$S; cp /work/scratch/s66/G63r5_model/sampling.json snap_$S/
  echo "[$(date -u +%H:%M)] step $S exported"
  (cd /work/main/reports/training/s67_ballistic && python ballistic_screen.py /work/scratch/s67/snap_$S)
done
