#!/usr/bin/env bash
# The extrapolation screen (screen_plan.txt; outputs in screens/). About 20 minutes on 2 cores.
set -eu
cd /work/main; . .venv/bin/activate
X=/work/scratch/s75; R=reports/training/s75_better; G63=reports/training/s63_deepen/G63_model
simdiff train deepen --model simdiff/assets/default_model --out $X/P63 --seed 63   # sha256 03a87cc0...
for l in 0.125 0.25 0.5 1; do simdiff train extrapolate --model $G63 --parent $X/P63 --lam $l --out $X/E$l; done
python $R/earth_probe.py jumps $G63 $X/E0.25 $X/E0.5 $X/E1 > $R/screens/probe_jumps.log
python $R/earth_probe.py walks $G63 $X/E0.25 $X/E0.125 > $R/screens/probe_walks.log
python $R/earth_probe.py jumps $X/E0.125 > $R/screens/probe_jumps2.log
for m in G63 E0.25 E0.125; do  # val, Earth, n 128, seed 9, the backbone alone, eta 1
  p=$X/$m; [ $m = G63 ] && p=$G63
  SIMDIFF_SCRATCH=/work/scratch/s39 SEEDS=9 STEPS=50 W=2.5 ALPHA=0 ETA=1 \
    python reports/training/s37_env_guidance/guard.py -9.81,0,0 1 $X/text_$m $p
  cp $X/text_$m/check.json $R/screens/text_$m.json
done
(cd reports/training/s53_extrapolate && PROBE_ALPHA=0 python nonjump_probe.py /work/main/$G63 $X/E0.25 $X/E0.125) \
  | grep jumping > $R/screens/nonjump.log
