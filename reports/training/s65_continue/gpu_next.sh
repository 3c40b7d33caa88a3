#!/usr/bin/env bash
# The next GPU session's command (session 65's plan, see README.md): G63 (session 63's 8 x 256 SimDiff model) carried
# as float16 and continued on one H200 without new layers (scripts/gpu_deepen.sh DEEPEN=0): its backbone 6,000 more
# steps on the corpus pack's `train_jj` split (session 63's second command: flying jumps 8x, in-place jumps +16, jogs
# 3x), where its loss was still falling at step 6,000, then its adapters on the new backbone (λ 10, μ 20 as G63).
# The pack in .gpu/corpus holds the splits train and train_jj (checked 2026-12-01 by unpacking it).
# Travel (measured 2026-12-01): code 2.67 MB + corpus pack 30.57 MB + aug packs 15.83 MB + captions 2.26 MB
# + G63 float16 13.43 MB = 64.76 MB = 61.8 MiB of the 64; reports/ and the default model must not travel.
# Run from the repository root, step by step.
set -eu
. .venv/bin/activate
simdiff train precision --model reports/training/s63_deepen/G63_model --out .gpu/G63 --dtype float16   # 13.43 MB
git rm -r -q --cached reports simdiff/assets/default_model
printf '/reports/\n/simdiff/assets/default_model/\n' >> .git/info/exclude
git commit -qm "TEMP: travel"
# device call (timeout_s 590; .gpu/ is untracked and not ignored, so it travels without carry):
#   OUT=$OUT PACK=.gpu/corpus AUG_PACK=".gpu/aug_weakg .gpu/aug_gen .gpu/aug_wind" TEXT_TABLE=.gpu/captions.safetensors \
#     INIT=.gpu/G63 DEEPEN=0 BB_SPLIT=train_jj BB_MINUTES=5.2 AD_MINUTES=2.4 SEED=66 PYTHON=python3 bash scripts/gpu_deepen.sh
# then, whatever the call gave:
#   git reset -q --mixed HEAD~1 && sed -i '\#^/reports/$#d; \#^/simdiff/assets/default_model/$#d' .git/info/exclude
#   for m in bb ad; do mkdir -p /work/scratch/s66/$m && cat $FILES_AT/$m.tar.part_* | tar -x -C /work/scratch/s66/$m; done
