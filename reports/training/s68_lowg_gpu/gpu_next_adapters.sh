#!/usr/bin/env bash
# The next GPU session's first command (session 68's plan, README.md): G63's adapters (G63's backbone frozen) trained
# on one H200 with the low-gravity replays of rule 75 added (aug_lowg: 418 low-g pairs with an Earth twin, 96 of them
# from Earth jumps >= 0.25 m), two variants side by side: G63's recipe (lambda 10, mu 20) and a stronger pair term
# (lambda 30, mu 20). Why: every inference-time variant of sessions 66-67 answers g -1.6 with an apex change of
# 0.32-0.37 m (the simulator asks 0.82-0.90 m for G63's Earth jumps) and CPU continuations (1,800 and 1,200 steps of
# batch 64) did not raise it; the adapters had 3,000 GPU steps on this backbone, the shipped ones over 10,000.
# Travel (measured 2026-12-01): code ~3 MB + G63 float16 13.4 MB + captions 2.3 MB + four aug packs 18.6 MB = ~37 MB;
# reports/, the default model and the corpus pack (not needed: the backbone is frozen) must not travel.
# Rehearsed on CPU (session 68, these packs, .gpu/G63_fp16, CONFIG a copy of ad68_gpu_config.json with steps 2,
# batch 4, save_every 1; DEVICE=cpu LOADER_WORKERS=0 MINUTES=3; 130 s on 2 cores, 90 s of it unpacking): both runs
# trained to step 2 from G63's adapters and came back as l10.tar.part_aa/ab and l30.tar.part_aa/ab (15.0 + 10.6 MiB
# each), an 8-layer SimDiff folder with the run's lambda / mu in train_config.json. The rehearsal caught a missing
# .gpu/G63_fp16 (session 65 had left it in its scratch): the first lines below make it.
# Session 69: the second run is now rule 79's data mix ("big": only the gravity sources whose Earth replay rises
# >= 0.1 m, aug_lowg's drawn 3x; reports/training/s69_bigjumps) instead of lambda 30, which tied lambda 10 on CPU;
# the big79 packs add 4.6 MB (~42 MB in all). scripts/gpu_adapters.sh takes a run's own packs from AUG_PACK_<NAME>.
# Run from the repository root, step by step (the device tool's run needs the repository as it is).
set -eu
. .venv/bin/activate
[ -d .gpu/G63_fp16 ] || simdiff train precision --model reports/training/s63_deepen/G63_model --out .gpu/G63_fp16 --dtype float16
[ -d .gpu/aug_lowg ] || simdiff train pack /work/scratch/s67/aug_lowg --out .gpu/aug_lowg --splits train --workers 2   # 3.24 MiB
for d in aug_lowg aug_weakg; do  # split big79: reports/training/s69_bigjumps/big_split.py (1.93 / 2.64 MiB)
  [ -d .gpu/${d}_big ] || simdiff train pack /work/scratch/s67/$d --out .gpu/${d}_big --splits big79 --workers 2
done
cp reports/training/s68_lowg_gpu/ad68_gpu_config.json .gpu/ad68_gpu_config.json
git rm -r -q --cached reports simdiff/assets/default_model
printf '/reports/\n/simdiff/assets/default_model/\n/.gpu/corpus/\n' >> .git/info/exclude
git commit -qm "TEMP: travel"
# device call (timeout_s 590; .gpu/ is untracked and not ignored, so it travels without carry; carry the mujoco-free
# project as it is: train adapters needs no simulator):
#   OUT=$OUT AUG_PACK=".gpu/aug_weakg .gpu/aug_gen .gpu/aug_wind .gpu/aug_lowg" TEXT_TABLE=.gpu/captions.safetensors \
#     BACKBONE=.gpu/G63_fp16 ADAPTERS_INIT=.gpu/G63_fp16 CONFIG=.gpu/ad68_gpu_config.json SPLIT=adapt SEED=68 \
#     AUG_PACK_big=".gpu/aug_lowg_big .gpu/aug_lowg_big .gpu/aug_lowg_big .gpu/aug_weakg_big .gpu/aug_wind .gpu/aug_gen" \
#     RUNS="l10:10:20 big:10:20" MINUTES=7 PYTHON=python3 bash scripts/gpu_adapters.sh
# then, whatever the call gave:
#   git reset -q --mixed HEAD~1 && sed -i '\#^/reports/$#d; \#^/simdiff/assets/default_model/$#d; \#^/.gpu/corpus/$#d' .git/info/exclude
#   for r in l10 big; do mkdir -p /work/scratch/s69/$r && cat $FILES_AT/$r.tar* | tar -x -C /work/scratch/s69/$r; done
# and screen each model (its sampling.json: rule 74's, /work/scratch/s66/G63r5_model/sampling.json) with
# reports/training/s67_ballistic/ballistic_screen.py (seeds 7700+), then a rule written before those screens (rules 77 and 79 are the pattern).
