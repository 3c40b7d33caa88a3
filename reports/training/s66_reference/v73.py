"""Rule 73's verdicts from one model-check report (exit 0 on a pass).
python v73.py text DIR    C' / C+: the report's r_precision_top3 and fid verdicts (issue bars, same run's GT)
python v73.py earth DIR W B: every verdict the report gives passes, and W (walking samples that jump) <= 3 of 64
python v73.py test DIR    T: every verdict passes -> SHIP; else SHIP only if each verdict the shipped test report passed
                          still passes and fid or jumps, which it failed, now passes"""
from __future__ import annotations

import json
import sys
from pathlib import Path

SHIPPED = Path("reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json")


def judged(path: Path) -> dict[str, dict]:
    """check name -> verdict, for the verdicts that were judged (passed is True or False)."""
    return {v["check"]: v for v in json.loads(path.read_text())["verdicts"] if v["passed"] is not None}


def line(v: dict) -> str:
    val = v["value"]
    val = f"{val:.4g}" if isinstance(val, float) else val
    return f"{v['check']} {val} {'pass' if v['passed'] else 'FAIL'}"


def main(kind: str, folder: str, extra: str | None = None) -> bool:
    rep = judged(Path(folder) / "check.json")
    print(folder, "|", "; ".join(line(v) for v in rep.values()))
    if kind == "text":
        ok = all(rep[k]["passed"] for k in ("r_precision_top3", "fid"))
    elif kind == "earth":
        walk = int(extra)
        ok = all(v["passed"] for v in rep.values()) and walk <= 3
        print(f"walk guard {walk} of 64 (bar 3)")
    elif kind == "test":
        ok = all(v["passed"] for v in rep.values())
        if not ok:
            old = judged(SHIPPED)
            kept = all(rep[k]["passed"] for k, v in old.items() if v["passed"])
            gained = any(rep[k]["passed"] for k in ("fid", "jumps") if not old[k]["passed"])
            print(f"not every verdict passes; shipped passes kept: {kept}; fid or jumps gained: {gained}")
            ok = kept and gained
        print("SHIP" if ok else "DO NOT SHIP")
    else:
        raise SystemExit(f"v73.py: unknown kind {kind!r} (text, earth or test)")
    print("PASS" if ok else "FAIL")
    return ok


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:]) else 1)
