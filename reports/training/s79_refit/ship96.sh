#!/usr/bin/env bash
# Rule 96's ship step, run only when v94.py test says SHIP: X96 becomes simdiff/assets/default_model (weights,
# config, provenance, sampling), its test check goes to test/X96/ and tests/test_default_model.py points at it.
set -euo pipefail
cd /work/main; . .venv/bin/activate
R=reports/training/s79_refit; V=reports/training/s78_captioned; T=/work/scratch/s39/eval11/T_X96; X=/work/scratch/s79/models/X96
python $V/v94.py test $T | grep -qx SHIP || { echo "ship96: T does not say SHIP" >&2; exit 1; }
D=simdiff/assets/default_model
cp $X/model.safetensors $X/config.json $X/provenance.json $D/
python -c "import json,sys; open(sys.argv[2],'w').write(json.dumps(json.load(open(sys.argv[1])), indent=2) + '\n')" \
  $X/sampling.json $D/sampling.json
mkdir -p $R/test/X96 && cp $T/check.json $T/check.md $R/test/X96/
sed -i 's#reports/training/s76_lambda/test/X93/check.json#reports/training/s79_refit/test/X96/check.json#' \
  tests/test_default_model.py
git status --short
