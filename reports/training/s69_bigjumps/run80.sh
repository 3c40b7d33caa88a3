#!/usr/bin/env bash
# Rule 80's stages (rule80.txt), only after A80's screen met the rule's bar: run73.sh with this rule's names and seeds.
cd /work/main
RULE=80 N=A80 SE=5 FB=4 AS=154 MODELS=/work/scratch/s69 R=reports/training/s69_bigjumps STAGES="gate A C' B C+ T" \
  bash reports/training/s66_reference/run73.sh
