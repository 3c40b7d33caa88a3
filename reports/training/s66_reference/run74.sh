# Rule 74 (session 66; rule74.txt): G63r5 through rule 73's stages at s_e 5 / fallback 4, stage-A seeds 142 143.
RULE=74 N=G63r5 SE=5 FB=4 AS=142 bash reports/training/s66_reference/run73.sh
