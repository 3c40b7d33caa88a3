#!/bin/bash
cd /work/main && . .venv/bin/activate
E=/work/scratch/s29
/usr/bin/time -f "exp %e s" simdiff evaluate run configs/eval_env_response.json --corpus $E/corpus3 --evaluator $E/eval \
  --adapters /work/scratch/s38/drift/model --out-dir /work/scratch/s38/exp \
  --set 'models=[{"name":"drift (s38) + env guidance 2","model":"adapters","alpha":0.5,"steps":20,"env_guidance":2.0}]'
echo done > /work/scratch/s38/exp.done
