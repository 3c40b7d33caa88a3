#!/usr/bin/env bash
# after screen71.sh: stage-A sizes with the simulator on probe seeds 7700+ (n 48) for the X82 setting
set -u
while pgrep -f screen71.sh >/dev/null; do sleep 10; done
cd /work/main/reports/training/s71_split; . /work/main/.venv/bin/activate
nice -n 5 python size_screen.py /work/scratch/s70/X82_model --save /work/scratch/s71/joints_X82.npz | tee -a sizes.log
