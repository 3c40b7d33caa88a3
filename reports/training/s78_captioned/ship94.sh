#!/usr/bin/env bash
# Rule 94's ship step, run only when v94.py test says SHIP: X94 becomes simdiff/assets/default_model (weights,
# config, provenance, sampling), its test check goes to test/X94/ and tests/test_default_model.py points at it.
set -euo pipefail
cd /work/main; . .venv/bin/activate
R=reports/training/s78_captioned; T=/work/scratch/s39/eval11/T_X94; X=/work/scratch/s78/models/X94_${STEP:-400}
python $R/v94.py test $T | grep -qx SHIP || { echo "ship94: T does not say SHIP" >&2; exit 1; }
D=simdiff/assets/default_model
cp $X/model.safetensors $X/config.json $X/provenance.json $D/
python -c "import json,sys; open(sys.argv[2],'w').write(json.dumps(json.load(open(sys.argv[1])), indent=2) + '\n')" \
  $X/sampling.json $D/sampling.json
mkdir -p $R/test/X94 && cp $T/check.json $T/check.md $R/test/X94/
sed -i 's#reports/training/s76_lambda/test/X93/check.json#reports/training/s78_captioned/test/X94/check.json#' \
  tests/test_default_model.py
git status --short
