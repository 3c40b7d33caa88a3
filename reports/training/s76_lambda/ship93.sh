#!/usr/bin/env bash
# Rule 93's ship step, run only when v93.py test says SHIP: X93 becomes simdiff/assets/default_model (weights,
# config, provenance, sampling), its test check goes to test/X93/ and tests/test_default_model.py points at it.
# The tree stays <= 48 MiB (tests/test_repo_size.py): the per-sample env_response JSON reports move to history.
set -euo pipefail
cd /work/main; . .venv/bin/activate
R=reports/training/s76_lambda; T=/work/scratch/s39/eval11/T_X93; X=/work/scratch/s76/models/X93_model
python $R/v93.py test $T | grep -qx SHIP || { echo "ship93: T does not say SHIP" >&2; exit 1; }
D=simdiff/assets/default_model
cp $X/model.safetensors $X/config.json $X/provenance.json $D/
python - $X/sampling.json $D/sampling.json <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
open(sys.argv[2], "w").write(json.dumps(s, indent=2) + "\n")
PY
mkdir -p $R/test/X93 && cp $T/check.json $T/check.md $R/test/X93/
sed -i 's#reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json#reports/training/s76_lambda/test/X93/check.json#' tests/test_default_model.py
git status --short
