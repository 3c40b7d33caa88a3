#!/usr/bin/env bash
# Rule 92 (rule92.txt): X90 through A, B', C+ and T with run90.sh's stages (gate and C''' carried from rules 90 and 91).
set -u
cd /work/main; . .venv/bin/activate
M=/work/scratch/s75/models/X90_model; OUT=reports/training/s75_better/rule92_stages.txt
sha256sum $M/model.safetensors | grep -q ^856504f9169ba456 || { echo "X90's weights are not rule 90's" >&2; exit 1; }
echo "rule 92: gate carried from rule 90 (PASS); C''' own R@3 bar carried from rules 90 and 91 (PASS)" >> $OUT
RULE=92 N=X90 M=$M AS=164 STAGES="A B Cplus T" STAGES_OUT=$OUT bash reports/training/s74_sim_reference/run87.sh
