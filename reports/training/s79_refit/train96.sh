#!/usr/bin/env bash
# Rule 96's candidates (rule96.txt): X95's Sim Encoder and adapters continued on X95's frozen backbone on train88.sh's
# mix and recipe (packs.sh's rebuilt packs, split big79), seed 96. Exports at SNAPS (default 300 600) go to
# /work/scratch/s79/snap_S with X95's sampling.json. Resumable: run again.
set -u
cd /work/scratch/s79; . /work/main/.venv/bin/activate
M=${M:-/work/main/reports/training/s78_captioned/X95_model}
sha256sum $M/model.safetensors | grep -q ^5801f52673e8d161 || { echo "X95's weights do not hash to 5801f526...; run scripts/restore_report_weights.sh" >&2; exit 1; }
for S in ${SNAPS:-300 600}; do
  SNAP=/work/scratch/s79/snap_$S
  [ -f $SNAP/model.safetensors ] && continue
  nice -n 5 python -m simdiff train adapters \
    --data aug_lowg aug_lowg aug_lowg aug_weakg aug_wind aug_gen aug_lowloc aug_lowloc aug_lowgen aug_lowgen \
    --split big79 --init $M --adapters-init $M --out /work/scratch/s79/ad96 \
    --config /work/main/reports/training/s67_ballistic/ad67_config.json --steps $S --seed 96 \
    --env-pairs 10 --env-pairs-drift 20 --twin-frames overlap --pair-twins wind --drift-pairs wind --cross-twins 0.5 \
    --no-progress --loader-workers 1 || exit 1
  rm -rf $SNAP.tmp; cp -r /work/scratch/s79/ad96/model $SNAP.tmp; cp $M/sampling.json $SNAP.tmp/; mv $SNAP.tmp $SNAP
  echo "[$(date -u +%H:%M)] step $S exported"
done
