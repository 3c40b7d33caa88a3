"""Rule 94's verdicts from one model-check report, recomputed with today's verdict code
(simdiff/eval/model_check/verdict.py: walk and run speeds per prompt against the corpus train clips captioned with it,
session 78). Reports written before session 77 lack those clips' quartiles; they are filled in from the corpus
(captioned_speeds on corpus3) before the verdicts are recomputed. Exit 0 on a pass.
python v94.py earth DIR WG   B: every verdict the report gives passes, and WG (walking samples that jump) <= 3 of 64
python v94.py text DIR       C+: r_precision_top3 and fid pass
python v94.py test DIR       T: every verdict passes -> SHIP (and resolve); else SHIP only if every verdict the shipped
                             model's (X93's) test check passes under today's rules still passes and run_speed, which it
                             fails, now passes"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.prompts import captioned_speeds, quartiles
from simdiff.eval.model_check.verdict import figures, verdicts

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "s66_reference"))
import v73  # noqa: E402  (rule 73's text and earth clauses)

SHIPPED = Path(__file__).resolve().parents[1] / "s76_lambda" / "test" / "X93" / "check.json"
CORPUS = Path(os.environ.get("SIMDIFF_SCRATCH", "/work/scratch/s39")) / "corpus3"


def filled(path: Path) -> dict:
    """The report at ``path`` with the captioned clips' quartiles filled in where it lacks them."""
    report = json.loads(path.read_text())
    types = (report.get("speeds") or {}).get("types") or {}
    if any("per_prompt_corpus_captioned" not in t for t in types.values()):
        captioned = captioned_speeds(CORPUS, SPEED_PROMPTS)
        for t in types.values():
            t["per_prompt_corpus_captioned"] = {p: quartiles(captioned.get(p, [])) for p in t["prompts"]}
    return report


def judged(path: Path) -> dict[str, dict]:
    """check name -> verdict under today's rules, for the verdicts that were judged (passed True or False)."""
    return {v["check"]: v for v in verdicts(figures(filled(path))) if v["passed"] is not None}


def line(v: dict) -> str:
    def fmt(x: object) -> str:
        return f"{x:.4g}" if isinstance(x, float) else "[" + ", ".join(map(fmt, x)) + "]" if isinstance(x, list) else str(x)
    return f"{v['check']} {fmt(v['value'])} {'pass' if v['passed'] else 'FAIL'}"


def main(kind: str, folder: str, extra: str | None = None) -> bool:
    """text and earth: rule 73's clauses (v73.py) on today's verdicts; test: rule 94's own clause."""
    v73.judged, v73.line = judged, line
    if kind != "test":
        return v73.main(kind, folder, extra)
    rep = judged(Path(folder) / "check.json")
    print(folder, "|", "; ".join(line(v) for v in rep.values()))
    print("\n".join(f"  {k}: {rep[k]['detail']}" for k in ("walk_speed", "run_speed") if k in rep))
    ok = all(v["passed"] for v in rep.values())
    if not ok:
        old = judged(SHIPPED)
        kept = all(rep[k]["passed"] for k, v in old.items() if v["passed"] and k in rep)
        gained = rep["run_speed"]["passed"] and not old["run_speed"]["passed"]
        print(f"not every verdict passes; X93's test passes kept: {kept}; run_speed gained: {gained}")
        ok = kept and gained
    print("SHIP" if ok else "DO NOT SHIP")
    print("PASS" if ok else "FAIL")
    return ok


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:]) else 1)
