# Rule 76 (session 67; rule76.txt): G63b (G63's weights, reference anchor at anchor_alpha 0, ballistic 1, s_e 5 /
# fallback 4: the screens' choice by the rule) through the gate, A, C', B (its own Earth draw), C+ and T.
RULE=76 N=G63b SE=5 FB=4 AS=146 BALLISTIC=1 BDRAW=/work/scratch/s39/eval11/B_G63b MODELS=/work/scratch/s67 \
  R=reports/training/s67_ballistic STAGES="gate A C' B C+ T" bash reports/training/s66_reference/run73.sh
