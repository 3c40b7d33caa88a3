"""Rule 87's stage B' from one model-check report: every verdict passes except jumps, jumps >= 0.458 (the shipped
J40m's val stage B, 44 of 96, session 62), and the walk guard <= 3 of 64. Exit 0 on a pass.
python v87.py DIR W"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "s66_reference"))
from v73 import judged, line  # noqa: E402  (rule 73's verdict reading and line format)

JUMPS_SHIPPED_VAL = 44 / 96
folder, walk = Path(sys.argv[1]), int(sys.argv[2])
rep = judged(folder / "check.json")
print(folder, "|", "; ".join(line(v) for v in rep.values()))
others = all(v["passed"] for k, v in rep.items() if k != "jumps")
jumps = rep["jumps"]["value"] >= JUMPS_SHIPPED_VAL - 1e-9
print(f"others pass: {others}; jumps {rep['jumps']['value']:.3f} >= {JUMPS_SHIPPED_VAL:.3f}: {jumps}; "
      f"walk guard {walk} of 64 (bar 3)")
ok = others and jumps and walk <= 3
print("PASS" if ok else "FAIL")
sys.exit(0 if ok else 1)
