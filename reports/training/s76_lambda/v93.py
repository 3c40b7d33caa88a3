"""Rule 93's verdicts from one model-check report, against the shipped model's test check under today's rules
(reports/training/s68_lowg_gpu/test_J40m: evaluator 1 as rebuilt since session 65, length-matched speeds). Exit 0 on a pass.
python v93.py earth DIR WG   B'': every verdict that report passes (sliding, skate ratio, R@3, walk speed) and FID and
                             jumps pass; WG (walking samples that jump) <= 3 of 64; run speed reported, not judged
python v93.py test DIR       T: every verdict passes -> SHIP (and resolve); else SHIP only if every verdict that report
                             passes still passes and FID or jumps, which it fails, now passes"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "s66_reference"))
import v73  # noqa: E402  (rule 73's verdicts; its test clause is rule 93's with this module's reference)
from v73 import judged, line  # noqa: E402

SHIPPED = Path(__file__).resolve().parents[1] / "s68_lowg_gpu" / "test_J40m" / "check.json"


def main(kind: str, folder: str, extra: str | None = None) -> bool:
    if kind not in ("earth", "test"):
        raise SystemExit(f"v93.py: unknown kind {kind!r} (earth or test)")
    if kind == "test":
        v73.SHIPPED = SHIPPED
        return v73.main("test", folder)
    rep, old = judged(Path(folder) / "check.json"), judged(SHIPPED)
    print(folder, "|", "; ".join(line(v) for v in rep.values()))
    kept = all(rep[k]["passed"] for k, v in old.items() if v["passed"] and k in rep)
    gained = {k: rep[k]["passed"] for k in ("fid", "jumps")}
    walk = int(extra)
    ok = kept and all(gained.values()) and walk <= 3
    print(f"shipped test passes kept: {kept}; fid, jumps: {gained}; walk guard {walk} of 64 (bar 3); "
          f"run speed {'pass' if rep['run_speed']['passed'] else 'FAIL'} (reported)")
    print("PASS" if ok else "FAIL")
    return ok


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:]) else 1)
