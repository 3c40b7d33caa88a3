#!/usr/bin/env bash
# Rule 79's model A79 (rule79.txt): G63's adapters continued on CPU from G63 on a mix weighted to the larger jumps
# (split big79, big_split.py; aug_lowg listed 3x), session 67's recipe otherwise (lambda 10, mu 20, batch 64), seed 69.
# Snapshots at SNAPS (default 600 then 1200) are exported with rule 74's sampling.json and screened
# (ballistic_screen.py, seeds 7700+); stops after the first snapshot that meets the rule's screen bar. Resumable.
set -u
cd /work/scratch/s67; . /work/main/.venv/bin/activate
M=/work/main/reports/training/s63_deepen/G63_model
R=/work/main/reports/training/s69_bigjumps
for S in ${SNAPS:-600 1200}; do
  nice -n 5 python -m simdiff train adapters --data aug_lowg aug_lowg aug_lowg aug_weakg aug_wind aug_gen --split big79 \
    --init $M --adapters-init $M --out /work/scratch/s69/ad79 \
    --config /work/main/reports/training/s67_ballistic/ad67_config.json --steps $S --seed 69 \
    --env-pairs 10 --env-pairs-drift 20 --text-table /work/main/.gpu/captions.safetensors --no-progress \
    --loader-workers 1 || exit 1
  rm -rf /work/scratch/s69/snap_$S; cp -r /work/scratch/s69/ad79/model /work/scratch/s69/snap_$S
  cp /work/scratch/s66/G63r5_model/sampling.json /work/scratch/s69/snap_$S/
  echo "[$(date -u +%H:%M)] step $S exported"
  L=$( (cd /work/main/reports/training/s67_ballistic && python ballistic_screen.py /work/scratch/s69/snap_$S \
    --dump /work/scratch/s69/dump79_$S.json) | tee -a $R/screens.log | tail -1)
  echo "$L"
  python - "$L" <<'PY' && { rm -rf /work/scratch/s69/A79_model; cp -r /work/scratch/s69/snap_$S /work/scratch/s69/A79_model; echo "A79 = step $S"; exit 0; }
import json, sys
d = json.loads(sys.argv[1])
print(d)
sys.exit(0 if d["raw"]["apex_change_median_m"] >= 0.45 and d["raw"]["rise_both"] >= 43 else 1)
PY
done
echo "rule 79: no snapshot met the screen bar -> no draws"
