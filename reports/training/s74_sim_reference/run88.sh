#!/usr/bin/env bash
# Rule 88 (rule88.txt): X88 through the gate, A (seeds 162 163), C'' (seeds 5 6), B', C+ and T by run87.sh's stages,
# only when probe88.sh's probe passed (rule 88's three conditions, judged by hand in probe88.log and recorded in
# rule88_stages.txt before this runs).
RULE=88 N=X88 M=/work/scratch/s74/models/X88_model CPP_SEEDS="5 6" AS=162 STAGES=${STAGES:-"gate A Cpp B Cplus T"} \
  bash /work/main/reports/training/s74_sim_reference/run87.sh
