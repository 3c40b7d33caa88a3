#!/usr/bin/env bash
# Rule 98 (rule98.txt): the screens (screen98.sh -> choice98.txt), then X98 = the chosen folder through the gate, A, B,
# T and C+ with run87.sh's stages at its edit_t and s_e; verdict lines in rule98_stages.txt. Re-running skips every
# screen and draw on disk.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s80_env_scale; OUT=$R/rule98_stages.txt
[ -f $R/choice98.txt ] || bash $R/screen98.sh || exit 1
F=$(sed -n 's/^choice: \(\/[^ ]*\) margin.*/\1/p' $R/choice98.txt)
[ -n "$F" ] || { grep -q "no candidate" $OUT 2>/dev/null || echo "rule 98: no candidate (choice98.txt)" | tee -a $OUT; exit 0; }
M=/work/scratch/s80/models/X98
if [ ! -d $M ]; then
  mkdir -p /work/scratch/s80/models && rm -rf $M.tmp && cp -r $F $M.tmp && mv $M.tmp $M
  echo "X98 = $F ($(sha256sum $M/model.safetensors | cut -c1-16); $(cat $M/sampling.json))" | tee -a $OUT
fi
read -r ET SE < <(python -c "import json,sys; d=json.load(open('$M/sampling.json')); print(d['edit_t'], d['env_guidance'])")
RULE=98 N=X98 M=$M SE=$SE EDIT_T=$ET AS=176 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="14 15" \
  B_VERDICT="python reports/training/s78_captioned/v94.py earth" T_VERDICT="python reports/training/s78_captioned/v94.py test" \
  STAGES="${STAGES:-gate A B T Cplus}" STAGES_OUT=$OUT bash reports/training/s74_sim_reference/run87.sh
