#!/usr/bin/env bash
# Rule 93 (rule93.txt): X93 = X90's weights at guidance 3.0 through A (seeds 166 167), B'' (seeds 4 5), C+ and T with
# run87.sh's stages; verdict lines in rule93_stages.txt. Re-running skips every draw on disk.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s76_lambda; X=/work/scratch/s76/models/X93_model
K=$R/X93_model  # the committed copy (scripts/restore_report_weights.sh brings its weights back from history)
if [ ! -f $X/model.safetensors ] && [ -f $K/model.safetensors ]; then mkdir -p $X && cp $K/* $X/; fi
if [ ! -f $X/model.safetensors ]; then  # X90 (rule90.txt's two commands) + guidance 3.0
  [ -f /work/scratch/s75/models/X90_model/model.safetensors ] || { echo "run scripts/restore_report_weights.sh or build X90 first (s75_better/run90.sh's commands)" >&2; exit 1; }
  mkdir -p $X && cp /work/scratch/s75/models/X90_model/* $X/ &&
    python -c "import json,sys; p=sys.argv[1]; s=json.load(open(p)); s['guidance']=3.0; open(p,'w').write(json.dumps(s)+'\n')" $X/sampling.json
fi
sha256sum $X/model.safetensors | grep -q ^856504f9169ba456 || { echo "X93's weights are not X90's" >&2; exit 1; }
grep -q '"guidance": 3.0' $X/sampling.json || { echo "X93's guidance is not 3.0" >&2; exit 1; }
RULE=93 N=X93 M=$X AS=166 GUIDANCE=3.0 PROBE_W=3.0 B_SEEDS="4 5" B_VERDICT="python $R/v93.py earth" \
  T_VERDICT="python $R/v93.py test" STAGES="A B Cplus T" STAGES_OUT=$R/rule93_stages.txt \
  bash reports/training/s74_sim_reference/run87.sh
