"""PASS/FAIL of issue 14's "done when" checks, computed from the measured numbers only.

:func:`figures` pulls the numbers out of a check report; :func:`verdicts` applies the rules to
them. A check whose numbers are missing (a section not run) or undefined (NaN) is ``n/a``
(``passed`` None), never a pass.
"""

from __future__ import annotations

import math
from typing import Any

RULES: dict[str, str] = {
    "sliding": "generated sliding on its own floor ≤ 1.0 mm/frame",
    "skate_ratio": "generated skate ratio ≤ 2 × ground truth's",
    "r_precision_top3": "generated R@3 ≥ 0.8 × ground truth's",
    "fid": "generated FID ≤ 3 × ground truth's FID floor (same n)",
    "jumps": "≥ 70 % of jump/hop samples fly ≥ 0.2 s with the pelvis ≥ 15 cm above standing",
    "walk_speed": ("each walk prompt's sample median speed within [Q1, Q3] of the corpus train clips captioned with it "
                   "(≥ 5 clips; else with any walk prompt; else the train walks of about the samples' length)"),
    "run_speed": ("each run prompt's sample median speed within [Q1, Q3] of the corpus train clips captioned with it "
                  "(≥ 5 clips; else with any run prompt; else the train runs of about the samples' length)"),
    "gravity_rise": "g = −1.6 vs −9.81 (same seed): ≥ 80 % of jump samples raise apex gain and flight time",
    "gravity_size": "median generated/simulated change ≥ 0.5 for apex gain and for flight time",
    "wind_downwind": "±10 N wind (w_x, w_y): ≥ 80 % of walk samples drift downwind",
    "generate_speed": "`simdiff generate` ≤ 10 s wall (benchmarks/bench_generate.py, median)",
}


CAPTIONED_MIN = 5
"""Fewest corpus train clips captioned with a prompt for the speed verdicts to judge that prompt by them (session 78).
A prompt with fewer is judged by the clips captioned with any prompt of its motion type (the check's other plain
prompts, e.g. "a person walks forward" for "a person is walking straight ahead"), and when those are fewer too, or
in reports written before session 77, by the clips of its type of about the samples' length, as every prompt was
from session 65 to 77. Why captions first: corpus3's long runs are all elderly or weary runs and its long walks
mix in elderly and exhausted ones, while the clips carrying the check's plain captions move at plain speeds
(reports/training/s77_run_speed, s78_captioned)."""

HOVER_MM = 5.0
"""Mean floating (mm) above the ground truth's beyond which the sliding figure is n/a (the metric's
5 mm contact slack)."""


def _num(value: Any) -> float | None:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _verdict(check: str, value: Any, threshold: Any, ok: bool | None, detail: str = "") -> dict[str, Any]:
    return {"check": check, "rule": RULES[check], "value": value, "threshold": threshold, "passed": ok, "detail": detail}


def _at_most(check: str, value: Any, limit: Any, detail: str = "") -> dict[str, Any]:
    v, lim = _num(value), _num(limit)
    return _verdict(check, v, lim, None if v is None or lim is None else v <= lim, detail)


def _at_least(check: str, value: Any, limit: Any, detail: str = "") -> dict[str, Any]:
    v, lim = _num(value), _num(limit)
    return _verdict(check, v, lim, None if v is None or lim is None else v >= lim, detail)


def _sliding(f: dict[str, Any]) -> dict[str, Any]:
    """Sliding ≤ 1.0 mm/frame, measured on each motion's own floor
    (:func:`simdiff.motion.metrics.own_floor_metrics`): CLoSD's sliding counts only frame pairs
    whose lowest joint is within 5 mm of y = 0, so samples that hover 2 cm up score 0 however
    their feet skate. Reports written before the own-floor figure existed fall back to CLoSD's
    sliding, n/a when the samples float more than :data:`HOVER_MM` above the ground truth."""
    own = _num(f.get("sliding_own_floor"))
    if own is not None:
        return _at_most("sliding", own, 1.0, f"mm/frame on the samples' own floor (GT {_fmt(f.get('gt_sliding_own_floor'))}; "
                                              f"CLoSD's sliding {_fmt(f.get('sliding'))}, own floor "
                                              f"{_fmt(f.get('own_floor'))} mm above y = 0)")
    v = _at_most("sliding", f.get("sliding"), 1.0, "mm/frame (CLoSD's; no own-floor figure in this report)")
    fl, gt_fl = _num(f.get("floating")), _num(f.get("gt_floating"))
    if v["passed"] and fl is not None and gt_fl is not None and fl - gt_fl > HOVER_MM:
        v["passed"] = None
        v["detail"] = (f"mm/frame; n/a: the samples hover (floating {fl:.1f} mm vs ground truth {gt_fl:.1f} mm), "
                       "so few frames are within 5 mm of the floor")
    return v


def _speed(f: dict[str, Any], kind: str) -> dict[str, Any]:
    """Walk / run speed, per prompt (``{kind}_captioned``: rows of prompt, sample median, Q1, Q3 and count of the
    clips captioned with it): against its captioned clips when there are :data:`CAPTIONED_MIN`, else against the
    clips captioned with any of the type's prompts (``{kind}_captioned_pool``: Q1, Q3, count) when there are that
    many, else against the type's length-matched clips (``{kind}_corpus_q1`` / ``_q3``). Reports without per-prompt
    rows judge the type's median against the length-matched clips. Value: the medians; threshold: the [Q1, Q3]
    each was held to."""
    length = [_num(f.get(f"{kind}_corpus_q1")), _num(f.get(f"{kind}_corpus_q3"))]
    p1, p3, pn = f.get(f"{kind}_captioned_pool") or [None, None, 0]
    rows = f.get(f"{kind}_captioned") or [[f"{kind} samples", f.get(f"{kind}_median"), None, None, 0]]
    meds, bands, notes, judged = [], [], [], []
    for prompt, med, c1, c3, n in rows:
        if (_num(n) or 0) >= CAPTIONED_MIN:
            band, ref = [_num(c1), _num(c3)], f"{int(n)} clips captioned so"
        elif (_num(pn) or 0) >= CAPTIONED_MIN:
            band, ref = [_num(p1), _num(p3)], f"{int(pn)} clips captioned with a {kind} prompt"
        else:
            band, ref = length, "clips of about the samples' length"
        m = _num(med)
        ok = None if m is None or None in band else band[0] <= m <= band[1]
        meds.append(m)
        bands.append(band)
        judged.append(ok)
        notes.append(f"{prompt}: {_fmt(m)} vs [{_fmt(band[0])}, {_fmt(band[1])}] of {ref}: "
                     f"{ {True: 'inside', False: 'outside', None: 'n/a'}[ok]}")
    ok = None if None in judged else all(judged)
    if len(rows) == 1 and not f.get(f"{kind}_captioned"):
        return _verdict(f"{kind}_speed", meds[0], bands[0], ok, "m/s; " + notes[0])
    return _verdict(f"{kind}_speed", meds, bands, ok, "m/s; " + "; ".join(notes))


def _fmt(value: Any) -> str:
    v = _num(value)
    return "n/a" if v is None else f"{v:.3g}"


def verdicts(f: dict[str, Any]) -> list[dict[str, Any]]:
    """Apply every rule of :data:`RULES` to the flat figures ``f`` (see :func:`figures` for the keys).

    Returns:
        one dict per check: check, rule, value, threshold (the number ``value`` is compared with),
        passed (True / False / None = n/a), detail.
    """
    def scaled(key: str, factor: float) -> float | None:
        v = _num(f.get(key))
        return None if v is None else v * factor

    out = [
        _sliding(f),
        _at_most("skate_ratio", f.get("skate_ratio"), scaled("gt_skate_ratio", 2.0), f"GT {f.get('gt_skate_ratio')}"),
        _at_least("r_precision_top3", f.get("r_precision_top3"), scaled("gt_r_precision_top3", 0.8),
                  f"GT {f.get('gt_r_precision_top3')}"),
        _at_most("fid", f.get("fid"), scaled("gt_fid", 3.0), f"GT floor {f.get('gt_fid')}"),
        _at_least("jumps", f.get("jump_fraction"), 0.7),
    ]
    out += [_speed(f, kind) for kind in ("walk", "run")]
    floats, glide = f.get("gravity_never_touch"), f.get("gravity_glides")
    out.append(_at_least("gravity_rise", f.get("gravity_rise_fraction"), 0.8,
                         "" if floats is None else f"{floats} of {f.get('gravity_n')} samples never touch the floor at "
                                                   "g = −1.6 and do not count as rising"
                                                   + ("" if glide is None else f"; {glide} glide and do not either")))
    apex, flight = _num(f.get("gravity_ratio_apex")), _num(f.get("gravity_ratio_flight"))
    size_ok = None if apex is None or flight is None else apex >= 0.5 and flight >= 0.5
    out.append(_verdict("gravity_size", [apex, flight], 0.5, size_ok, "[apex gain, flight time]"))
    out.append(_at_least("wind_downwind", f.get("wind_downwind_fraction"), 0.8))
    out.append(_at_most("generate_speed", f.get("generate_wall_s"), 10.0, "s"))
    return out


def figures(report: dict[str, Any]) -> dict[str, Any]:
    """The flat numbers :func:`verdicts` reads, from a check report (missing sections give None)."""
    f: dict[str, Any] = {}
    split = report.get("test_split") or {}
    gen, gt = split.get("generated") or {}, split.get("ground_truth") or {}
    for key in ("sliding", "skate_ratio", "r_precision_top3", "fid", "floating", "sliding_own_floor", "own_floor",
                "never_touch"):
        f[key] = (gen.get(key) or {}).get("mean")
        f[f"gt_{key}"] = (gt.get(key) or {}).get("mean")
    f["jump_fraction"] = ((report.get("jumps") or {}).get("overall") or {}).get("fraction")
    types = (report.get("speeds") or {}).get("types") or {}
    for kind in ("walk", "run"):
        t = types.get(kind) or {}
        f[f"{kind}_median"] = (t.get("samples") or {}).get("median")
        f[f"{kind}_corpus_q1"] = (t.get("corpus_train") or {}).get("q1")
        f[f"{kind}_corpus_q3"] = (t.get("corpus_train") or {}).get("q3")
        mine, ref = t.get("per_prompt") or {}, t.get("per_prompt_corpus_captioned") or {}
        f[f"{kind}_captioned"] = [[p, (mine.get(p) or {}).get("median"), q.get("q1"), q.get("q3"), q.get("n")]
                                  for p, q in ref.items()] or None
        pool = t.get("corpus_captioned_any_prompt") or {}
        f[f"{kind}_captioned_pool"] = [pool.get("q1"), pool.get("q3"), pool.get("n")] if pool else None
    grav = (report.get("response") or {}).get("gravity") or {}
    f["gravity_rise_fraction"] = grav.get("rise_fraction")
    f["gravity_never_touch"] = (grav.get("never_touch") or {}).get("low_g")
    f["gravity_n"] = grav.get("n")
    runs = (report.get("response") or {}).get("gravity_runs") or {}
    f["runs_never_touch_low_g"] = (runs.get("never_touch") or {}).get("low_g")
    f["gravity_glides"] = (grav.get("glides") or {}).get("low_g")
    f["runs_glides_low_g"] = (runs.get("glides") or {}).get("low_g")
    ratios = grav.get("ratios") or {}
    f["gravity_ratio_apex"] = (ratios.get("apex_gain_m") or {}).get("median_ratio")
    f["gravity_ratio_flight"] = (ratios.get("flight_s") or {}).get("median_ratio")
    f["wind_downwind_fraction"] = ((report.get("response") or {}).get("wind") or {}).get("downwind_fraction")
    speed = ((report.get("generation_speed") or {}).get("summary") or {}).get("wall_s") or {}
    f["generate_wall_s"] = speed.get("median")
    return f
