#!/usr/bin/env bash
# Session 71 information screens (probe seeds 7700+, n 48 pairs, eta 1): X81's 600-step weights under other samplings.
set -u
O=/work/scratch/s71; R=/work/main/reports/training/s71_split
cd /work/main/reports/training/s67_ballistic; . /work/main/.venv/bin/activate
run() { # name sampling-json
  F=$O/$1; rm -rf $F; cp -r /work/scratch/s70/snap_600 $F; echo "$2" > $F/sampling.json
  nice -n 5 python ballistic_screen.py $F --eta 1 --dump $O/dump_$1.json | tee -a $R/screens.log
}
run X81_ref_a05_se5 '{"alpha": 0.5, "guidance": 2.5, "steps": 50, "sampler": "ddim", "foot_lock": 1.0, "env_guidance": 5.0, "anchor": "reference", "anchor_alpha": 0.0}'
run X81_edit_a07 '{"alpha": 0.7, "guidance": 2.5, "steps": 50, "sampler": "ddim", "foot_lock": 1.0, "env_guidance": 1.0, "anchor": "edit", "anchor_alpha": 0.0, "edit_t": 800}'
run X81_edit_a05 '{"alpha": 0.5, "guidance": 2.5, "steps": 50, "sampler": "ddim", "foot_lock": 1.0, "env_guidance": 1.0, "anchor": "edit", "anchor_alpha": 0.0, "edit_t": 800}'
run X81_ref_a1_se2 '{"alpha": 1.0, "guidance": 2.5, "steps": 50, "sampler": "ddim", "foot_lock": 1.0, "env_guidance": 2.0, "anchor": "reference", "anchor_alpha": 0.0}'
