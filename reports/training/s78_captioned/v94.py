"""Rule 94's verdicts from one model-check report, recomputed with today's verdict code
(simdiff/eval/model_check/verdict.py: walk and run speeds per prompt against the corpus train clips captioned with it,
session 78). Reports written before session 78 lack some of those clips' quartiles; they are filled in from the corpus
(captioned_speeds on corpus3) before the verdicts are recomputed. Rule 94 ran with the first session-78 rule (a prompt
with fewer than 5 captioned clips held to the length-matched clips); rule 95 with the second (to the clips captioned
with any prompt of its type first); rule94_stages.txt keeps what rule 94's screen printed. Exit 0 on a pass.
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
from simdiff.eval.model_check.prompts import captioned_speeds, pool_key, quartiles
from simdiff.eval.model_check.verdict import figures, verdicts

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "s66_reference"))
import v73  # noqa: E402  (rule 73's text and earth clauses)

SHIPPED = Path(__file__).resolve().parents[1] / "s76_lambda" / "test" / "X93" / "check.json"
CORPUS = Path(os.environ.get("SIMDIFF_SCRATCH", "/work/scratch/s39")) / "corpus3"


def filled(path: Path) -> dict:
    """The report at ``path`` with the captioned clips' quartiles filled in where it lacks them."""
    report = json.loads(path.read_text())
    types = (report.get("speeds") or {}).get("types") or {}
    if any("corpus_captioned_any_prompt" not in t for t in types.values()):
        captioned = captioned_speeds(CORPUS, SPEED_PROMPTS)
        for kind, t in types.items():
            t["per_prompt_corpus_captioned"] = {p: quartiles(captioned.get(p, [])) for p in t["prompts"]}
            t["corpus_captioned_any_prompt"] = quartiles(captioned.get(pool_key(kind), []))
    return report


def speed_verdict(types: dict, kind: str, medians: dict[str, float]) -> dict:
    """Today's ``{kind}_speed`` verdict for sample medians per prompt (m/s), against the references in ``types`` (a
    filled report's ``speeds.types``), through the model check's own figures / verdicts."""
    t = {**types[kind], "per_prompt": {p: {"median": m} for p, m in medians.items()}}
    return next(v for v in verdicts(figures({"speeds": {"types": {kind: t}}})) if v["check"] == f"{kind}_speed")


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
