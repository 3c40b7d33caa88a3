# The next GPU session's command for G63 (session 64's plan; see README.md): G63's adapters trained ~9 minutes on
# one H200 (about 12,000 steps of batch 128 at session 63's rate), two runs side by side (λ 10 / μ 20 as G63, and the
# same from G63's adapters with another seed) so the device returns a learning curve and a seed spread.
# Travel (measured 2026-12-01): code 2.5 MiB + aug packs and captions 17.3 MiB + G63 25.6 MiB = 45.4 MiB of the 64;
# reports/ (72 MiB) and the default model (13.5 MiB) must not travel. Run from the repository root, step by step.
set -eu
mkdir -p .gpu/G63 && cp reports/training/s63_deepen/G63_model/* .gpu/G63/
git rm -r -q --cached reports simdiff/assets/default_model
printf '/reports/\n/simdiff/assets/default_model/\n' >> .git/info/exclude
git commit -qm "TEMP: travel"
# device call (timeout_s 590; .gpu/ is untracked and not ignored, so it travels without carry):
#   OUT=$OUT AUG_PACK=".gpu/aug_weakg .gpu/aug_gen .gpu/aug_wind" TEXT_TABLE=.gpu/captions.safetensors \
#     BACKBONE=.gpu/G63 ADAPTERS_INIT=.gpu/G63 CONFIG=configs/adapters_paired_gpu_finetune.json SPLIT=adapt \
#     RUNS="long:10:20" MINUTES=8.5 SEED=64 PYTHON=python3 bash scripts/gpu_adapters.sh
# then, whatever the call gave:
#   git reset -q --mixed HEAD~1 && sed -i '\#^/reports/$#d; \#^/simdiff/assets/default_model/$#d' .git/info/exclude
#   cat $FILES_AT/long.tar.part_* > long.tar && tar -xf long.tar -C /work/scratch/s65/long
