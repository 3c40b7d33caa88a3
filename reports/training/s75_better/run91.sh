#!/usr/bin/env bash
# Rule 91 (rule91.txt): X90 through C''' (seeds 11 12, R@3 margin 0.03), A, B', C+ and T with run90.sh's stages.
RULE=91 CSEEDS="11 12" MARGIN=0.03 GATE=carried bash /work/main/reports/training/s75_better/run90.sh
