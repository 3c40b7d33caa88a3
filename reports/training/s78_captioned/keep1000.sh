#!/usr/bin/env bash
# Keeps train94's EMA export at step 1000 (the trainer overwrites model/ at every save) as /work/scratch/s78/fine1000.
RUN=/work/scratch/s77/train94; F=/work/scratch/s78/fine1000
until [ "$(cat $RUN/checkpoints/latest 2>/dev/null)" = "step_000001000" ]; do sleep 20; done
sleep 60; mkdir -p $F.tmp && cp $RUN/model/* $F.tmp/ && mv $F.tmp $F; echo "kept 1000 at $(date -u +%H:%M)"
