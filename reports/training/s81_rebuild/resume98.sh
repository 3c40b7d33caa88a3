#!/usr/bin/env bash
# Rule 98's stages from a fresh machine without the packs: X96's weights come from git history (restore script;
# session 81 rebuilt them bit for bit, sha256 bea4733b...), then rebuild81.sh does the rest (corpus3, X98's folder,
# evaluator 1, run98.sh), each step skipped when its output is on disk. The stage reports session 81 finished are kept
# in eval11/ here and put back into /work/scratch/s39/eval11 when missing, so run87.sh re-judges them without re-drawing
# (a model check resumes after its last finished section, so T's finished sections are reused too when on disk).
set -eu
cd /work/main; . .venv/bin/activate
X96=/work/scratch/s79/models/X96; D=reports/training/s79_refit/X96_model
if [ ! -f $X96/model.safetensors ]; then
  bash scripts/restore_report_weights.sh > /dev/null
  mkdir -p /work/scratch/s79/models && rm -rf $X96.tmp && cp -r $D $X96.tmp && mv $X96.tmp $X96
fi
mkdir -p /work/scratch/s39/eval11 /work/scratch/s74
[ -e /work/scratch/s74/X98_probe.log ] || cp reports/training/s81_rebuild/gate98_X98_probe.log /work/scratch/s74/X98_probe.log
for d in reports/training/s81_rebuild/eval11/*/; do
  t=/work/scratch/s39/eval11/$(basename $d); [ -e $t ] || cp -r $d $t
done
exec bash reports/training/s81_rebuild/rebuild81.sh
