#!/usr/bin/env bash
# Rule 80's model A80 (rule80.txt): G63's adapters continued on CPU from G63 with aug_self63 (self69.sh) added, rule 63's
# twin handling, 600 steps of batch 64, seed 69; exported with rule 74's sampling.json and screened (ballistic_screen.py,
# seeds 7700+). Waits for self69.sh. Resumable: run again.
set -u
O=/work/scratch/s69; R=/work/main/reports/training/s69_bigjumps
while pgrep -f self69.sh > /dev/null; do sleep 20; done
grep -q AUG_DONE $O/self69.log || { echo "augmentation did not finish"; exit 1; }
cd /work/scratch/s67; . /work/main/.venv/bin/activate
[ -f $O/aug_self63/adapt.txt ] || cp $O/aug_self63/first_try.txt $O/aug_self63/adapt.txt
M=/work/main/reports/training/s63_deepen/G63_model
nice -n 5 python -m simdiff train adapters --data aug_weakg aug_gen aug_wind aug_lowg $O/aug_self63 --split adapt \
  --init $M --adapters-init $M --out $O/ad80 --config /work/main/reports/training/s67_ballistic/ad67_config.json \
  --steps 600 --seed 69 --env-pairs 10 --env-pairs-drift 20 --twin-frames overlap --pair-twins wind --drift-pairs wind \
  --text-table /work/main/.gpu/captions.safetensors --no-progress --loader-workers 1 || exit 1
rm -rf $O/A80_model; cp -r $O/ad80/model $O/A80_model; cp /work/scratch/s66/G63r5_model/sampling.json $O/A80_model/
cp $O/ad80/train_log.jsonl $R/ad80_train_log.jsonl
echo "[$(date -u +%H:%M)] A80 exported"
(cd /work/main/reports/training/s67_ballistic && python ballistic_screen.py $O/A80_model --dump $O/dump80.json) \
  | tee -a $R/screens.log
