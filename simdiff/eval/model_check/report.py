"""check.md: the model check as a readable report (every number from check.json)."""

from __future__ import annotations

import math
from typing import Any

from simdiff.eval.model_check.verdict import CAPTIONED_MIN


def _f(v: Any, digits: int = 3) -> str:
    if v is None:
        return "—"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_f(x, digits) for x in v) + "]"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    return "NaN" if math.isnan(x) else f"{x:.{digits}g}" if abs(x) >= 1000 else f"{x:.{digits}f}"


def _ci(s: dict[str, Any] | None, digits: int = 3) -> str:
    if not s:
        return "—"
    half = s.get("ci95")
    return _f(s.get("mean"), digits) + ("" if half is None or half != half else f" ± {_f(half, digits)}")


def _claim_line(report: dict[str, Any]) -> list[str]:
    problems = (report.get("test_split") or {}).get("claim_problems")
    if problems is None:
        return []
    if not problems:
        return ["The test-split settings can carry the issue's claim (n ≥ 256 or the whole split, ≥ 5 replications).", ""]
    return ["**These settings cannot carry the issue's claim:** " + "; ".join(problems) + ".", ""]


def _verdict_lines(report: dict[str, Any]) -> list[str]:
    lines = ["| check | rule | value | threshold | verdict |", "|---|---|---|---|---|"]
    for v in report["verdicts"]:
        mark = {True: "**PASS**", False: "**FAIL**", None: "n/a"}[v["passed"]]
        if v["passed"] is None and "n/a:" in (v.get("detail") or ""):
            mark += " (" + v["detail"].split("n/a:", 1)[1].strip() + ")"
        lines.append(f"| {v['check']} | {v['rule']} | {_f(v['value'])} | {_f(v['threshold'])} | {mark} |")
    return lines


def _split_lines(s: dict[str, Any]) -> list[str]:
    if not s or "skipped" in s:
        return [f"Not measured: {(s or {}).get('skipped', 'no result')}."]
    n = s["samples_per_replication"]
    size_note = (f"the whole split in batches of {s['batch_size']} ({n} of {s['split_size']}; fewer than the "
                 f"{s['n_requested']} asked)") if s["whole_split"] else f"{n} of {s['split_size']} {s['split']} motions"
    lines = [f"Split `{s['split']}`, {size_note} per replication, {s['replications']} replications (seeds "
             f"{', '.join(map(str, s['seeds']))}), samples at the GT lengths for the GT captions, {s['env']}. "
             f"Mean ± Student-t 95 % half-width over replications. FID floor: {s['fid_floor']}."]
    if not s["r_precision_comparable"]:
        lines.append(f"R-precision batch {s['batch_size']} (not 32): not comparable with protocol numbers.")
    lines += ["", "| metric | generated | ground truth | generated / GT (per replication) |", "|---|---|---|---|"]
    ratio = {"skate_ratio": "skate_ratio", "r_precision_top3": "r_precision_top3", "fid": "fid_over_floor",
             "sliding": "sliding_over_gt", "sliding_own_floor": "sliding_own_floor_over_gt"}
    for key in ("sliding", "sliding_own_floor", "own_floor", "skate_ratio", "penetration", "floating", "never_touch", "r_precision_top1", "r_precision_top3", "mm_dist",
                "fid", "diversity"):
        r = s["ratios"].get(ratio.get(key, ""))
        lines.append(f"| {key}{' (FID floor for GT)' if key == 'fid' else ''} | {_ci(s['generated'].get(key))} | "
                     f"{_ci(s['ground_truth'].get(key))} | {_ci(r) if r else ''} |")
    lines.append(f"\nGeneration: {_f(s['gen_s_per_sample'])} s per sample (batched).")
    return lines + _more_evaluator_lines(s.get("more_evaluators") or [])


def _more_evaluator_lines(more: list[dict[str, Any]]) -> list[str]:
    """The same motions scored by further evaluators (the verdicts use the first)."""
    if not more:
        return []
    lines = ["", "The same generated and GT motions scored by further evaluators (not used by the verdicts):", "",
             "| evaluator | R@3 generated | R@3 GT | FID generated | FID floor (GT) | FID / floor |", "|---|---|---|---|---|---|"]
    for m in more:
        g, t = m["generated"], m["ground_truth"]
        lines.append(f"| `{m['evaluator']['path']}` | {_ci(g.get('r_precision_top3'))} | {_ci(t.get('r_precision_top3'))} | "
                     f"{_ci(g.get('fid'))} | {_ci(t.get('fid'))} | {_ci(m['ratios'].get('fid_over_floor'))} |")
    return lines


def _jump_lines(j: dict[str, Any]) -> list[str]:
    r = j["rule"]
    lines = [f"{j['overall']['n']} samples of {j['frames']} frames at Earth φ. A sample jumps when a flight lasts "
             f"≥ {r['min_flight_s']} s and the pelvis rises ≥ {r['min_rise_m'] * 100:.0f} cm above its standing level "
             f"during it. Standing level: {r['standing_level']}. Interval: {r['interval']}.", "",
             "| prompt | n | jumps | fraction [95 %] | with flight ≥ 0.2 s | median flight s | median rise m | never touch floor |",
             "|---|---|---|---|---|---|---|---|"]
    for row in [*j["per_prompt"], j["overall"]]:
        lines.append(f"| {row['prompt']} | {row['n']} | {row['jumps']} | {_f(row['fraction'], 2)} "
                     f"{_f(row['wilson95'], 2)} | {row['with_flight']} | {_f(row['median_flight_s'], 2)} | "
                     f"{_f(row['median_rise_m'], 3)} | {row.get('never_touch', '—')} |")
    return lines


def _est(v: list[float]) -> str:
    """``estimate [low, high]`` of a bootstrap triple; ``—`` when undefined."""
    est, lo, hi = (_f(x, 2) for x in v)
    return "—" if est == "NaN" else est if lo == "NaN" else f"{est} [{lo}, {hi}]"


def _q(q: dict[str, Any]) -> str:
    return f"{_f(q['q1'], 2)} / {_f(q['median'], 2)} / {_f(q['q3'], 2)} (n {q['n']})"


def _speed_lines(s: dict[str, Any]) -> list[str]:
    if "skipped" in s:
        return [f"Not measured: {s['skipped']}."]
    lines = [f"Speed: {s['speed']}; {s['rule']}. Quartiles Q1 / median / Q3.", "",
             "| type | prompts | samples | corpus train clips of about that length | all lengths (no verdict) | median in IQR | "
             "never touch floor | jumping (corpus) |",
             "|---|---|---|---|---|---|---|---|"]
    for kind, t in s["types"].items():
        every = t.get("corpus_train_all_lengths")
        lines.append(f"| {kind} | {'; '.join(t['prompts'])} | {_q(t['samples'])} | {_q(t['corpus_train'])} | "
                     f"{'—' if every is None else _q(every)} | "
                     f"{'yes' if t['median_in_iqr'] else 'no'} | {t.get('never_touch', '—')} | "
                     f"{_jumping(t.get('jumping'))} |")
    if any(t.get("per_prompt_corpus_captioned") for t in s["types"].values()):
        lines += ["", "Per prompt, beside the corpus train clips captioned with the prompt itself, any length "
                  "(the speed verdicts hold each prompt with at least "
                  f"{CAPTIONED_MIN} such clips to them, the others to the clips captioned with any prompt of their "
                  "type, last row of each type, or when those are fewer to the length-matched clips above):", "",
                  "| prompt | samples | clips captioned so |", "|---|---|---|"]
        for kind, t in s["types"].items():
            lines += [f"| {p} | {_q(t['per_prompt'][p])} | {_q(ref) if ref['n'] else 'none'} |"
                      for p, ref in (t.get("per_prompt_corpus_captioned") or {}).items()]
            pool = t.get("corpus_captioned_any_prompt")
            if pool is not None:
                lines.append(f"| any {kind} prompt | {_q(t['samples'])} | {_q(pool) if pool['n'] else 'none'} |")
    return lines


def _jumping(j: dict[str, Any] | None) -> str:
    """'k of n (corpus f)' for the walk / run samples that jump; '—' in reports made before session 53."""
    if j is None:
        return "—"
    ref = j.get("corpus_train_fraction")
    return f"{j['jumps']} of {j['n']}" + ("" if ref is None else f" (corpus {_f(ref, 3)})")


def _response_lines(r: dict[str, Any]) -> list[str]:
    if "skipped" in r:
        return [f"Not measured: {r['skipped']}."]
    g, w = r["gravity"], r["wind"]
    lines = [f"Simulator: {r['simulator']}. Same noise for every φ; simulated change = the Earth sample re-tracked "
             "under φ minus it re-tracked under Earth.", "",
             f"**Gravity {_f(g['env'][0], 2)} vs −9.81** on the jump prompts: {g['rise_both']} of {g['n']} samples raise "
             f"both apex gain and flight time ({_f(g['rise_fraction'], 2)} {_f(g['wilson95'], 2)}; apex only "
             f"{g['rise_apex_only']}, flight only {g['rise_flight_only']}). Rollouts: "
             + ", ".join(f"{k} {v}" for k, v in sorted(g["rollouts"].items())) + "." + _never_touch(g), "",
             "| quantity | generated change Q1/med/Q3 | simulated change Q1/med/Q3 | median gen/sim | samples in ratio |",
             "|---|---|---|---|---|"]
    for q, v in g["ratios"].items():
        ci = f" {_f(v['ci95'], 2)}" if "ci95" in v else ""
        lines.append(f"| {q} | {_q(v['generated_change'])} | {_q(v['simulated_change'])} | {_f(v['median_ratio'], 2)}{ci} | "
                     f"{v['n_ratio']} (|Δsim| > {v['tolerance']}) |")
    lines += _airborne_lines(g, "jump") + _runs_lines(r.get("gravity_runs"))
    lines += ["", f"**Wind ±10 N** (w_x, w_y) on the walk prompts: {w['downwind']} of {w['n']} (sample, φ) pairs drift "
              f"downwind ({_f(w['downwind_fraction'], 2)} {_f(w['wilson95'], 2)}). Drift along the wind per 10 N, "
              f"Q1/med/Q3: generated {_q(w['drift_per_10n_generated_m'])} m, simulated "
              f"{_q(w['drift_per_10n_simulated_m'])} m; median ratio {_f(w['median_ratio_generated_to_simulated'], 2)}. "
              "Rollouts: " + ", ".join(f"{k} {v}" for k, v in sorted(w["rollouts"].items())) + "." + _fell_back(w), "",
              "| φ | downwind | generated m Q1/med/Q3 | simulated m Q1/med/Q3 | never touch floor | glide |",
              "|---|---|---|---|---|---|"]
    for env, v in w["per_env"].items():
        lines.append(f"| {env} | {v['downwind']} / {v['n']} | {_q(v['generated_m'])} | {_q(v['simulated_m'])} | "
                     f"{v.get('never_touch', '—')} | {v.get('glides', '—')} |")
    lines += ["", "Response scores (simdiff/eval/response.py; 95 % bootstrap over samples):", "",
              "| factor | quantity | pairs / with effect | sign agreement | slope ratio |", "|---|---|---|---|---|"]
    for s in [*g["scores"], *w["scores"]]:
        lines.append(f"| {s['factor']} | {s['quantity']} | {s['n_pairs']} / {s['n_effect']} | "
                     f"{_est(s['sign_agreement'])} | {_est(s['slope_ratio'])} |")
    return lines


def _never_touch(g: dict[str, Any]) -> str:
    """The gravity section's floor-contact sentence (reports before it existed: none)."""
    t = g.get("never_touch")
    if not t:
        return ""
    return (f" Samples that never touch the floor ({t['rule']}): {t['low_g']} of {g['n']} at {_f(g['env'][0], 2)}, "
            f"{t['earth']} at Earth; the simulator's {_f(g['env'][0], 2)} rollouts {t['simulated_low_g']} of "
            f"{t['simulated_tracked']} tracked." + _glides(g))


def _glides(g: dict[str, Any]) -> str:
    """The gravity sections' gliding sentence (reports before session 52: none)."""
    t = g.get("glides")
    if not t:
        return ""
    return (f" Samples that glide ({t['rule']}): {t['low_g']} of {g['n']} at {_f(g['env'][0], 2)}, "
            f"{t['earth']} at Earth." + _fell_back(g))


def _fell_back(r: dict[str, Any]) -> str:
    """How many samples off Earth were re-sampled at the fallback s_e (none before session 53 or without one)."""
    f = r.get("fell_back")
    if not f:
        return ""
    return f" Re-sampled at the fallback s_e {_f(f['s_e'], 2)} (floating or gliding): {f['samples']} of {f['of']}."


def _airborne_lines(g: dict[str, Any], what: str) -> list[str]:
    a = g.get("airborne_total_s")
    if not a:
        return []
    return ["", f"Time in flight (all flights) of the {what} samples that touch the floor, change at {_f(g['env'][0], 2)} "
                f"vs Earth, Q1/med/Q3: generated {_q(a['generated_change'])} s, simulated {_q(a['simulated_change'])} s."]


def _runs_lines(g: dict[str, Any] | None) -> list[str]:
    """The run prompts under low gravity: floor contact and flight time against the simulator's (no verdict)."""
    if not g:
        return []
    t = g["never_touch"]
    rollouts = ", ".join(f"{k} {v}" for k, v in sorted(g["rollouts"].items()))
    return ["", f"**Runs at g = {_f(g['env'][0], 2)}** (the run prompts, same noise as at Earth; no verdict): "
                f"{t['low_g']} of {g['n']} samples never touch the floor ({t['earth']} at Earth; the simulator's "
                f"rollouts {t['simulated_low_g']} of {t['simulated_tracked']} tracked). Rollouts: {rollouts}."
                + _glides(g)] + _airborne_lines(g, "run")[1:]


def _speed_of_generate(s: dict[str, Any]) -> list[str]:
    if "skipped" in s:
        return [f"Not measured: {s['skipped']}."]
    wall, cpu = s["summary"]["wall_s"], s["summary"]["cpu_s"]
    return [f"`{s['command']}` ({len(s['runs'])} runs, threads {s['threads']}): wall median {wall['median']} s, "
            f"CPU median {cpu['median']} s (benchmarks/bench_generate.py; load before/after "
            f"{s['machine']['loadavg_1min_before_after']})."]


def markdown(report: dict[str, Any]) -> str:
    """The whole report as Markdown."""
    c, p = report["settings"], report["provenance"]
    lines = [f"# Model check: {report['model']['path']}", "",
             f"Model kind: {report['model']['kind']}; corpus {report['corpus']}; evaluator {report['evaluator']['path']}; "
             f"DDIM {c['steps']} steps, guidance {c['guidance']}, α {c['alpha']}; seeds {c['seeds']}"
             + (f"; foot lock {c['foot_lock']}" if c.get("foot_lock") else "")
             + (f"; env guidance {c['env_guidance']}" if c.get("env_guidance", 1.0) != 1.0 else "")
             + (f"; guidance anchor {c['anchor']}" if c.get("anchor", "adapters") != "adapters" else "")
             + (f" at α {c['anchor_alpha']}" if c.get("anchor_alpha") else "")
             + (f" at t ≤ {c['anchor_t_max']}" if c.get("anchor_t_max") is not None else "")
             + (f", φ from t ≤ {c['edit_t']}" if c.get("edit_t") is not None else "")
             + (f"; DDIM η {c['eta']}" if c.get("eta") else "")
             + (f"; ballistic flight {c['ballistic']}" if c.get("ballistic") else "")
             + ("; **quick preset (smoke run, not a claim)**" if c["quick"] else "") + ".",
             f"Command: `{p['command']}`; commit {p['git_commit']}{' (dirty tree)' if p['git_dirty'] else ''}; "
             f"{p['machine']['cpus']} CPUs, torch threads {p['machine']['torch_threads']}; finished {report['finished']}.",
             "", "## Verdicts (issue 14, done when)", "", *_claim_line(report), *_verdict_lines(report),
             "", "## 1. Test split at Earth φ", "", *_split_lines(report["test_split"]),
             "", "## 2. Jump and hop prompts", "", *_jump_lines(report["jumps"]),
             "", "## 3. Walk and run speeds", "", *_speed_lines(report["speeds"]),
             "", "## 4. Physics response", "", *_response_lines(report["response"]),
             "", "## 5. Generation speed", "", *_speed_of_generate(report["generation_speed"]),
             "", "Wall seconds per section (a stored section shows the time it took when measured): "
             + ", ".join(f"{k} {float(v):.1f}" for k, v in report["timings_s"].items()) + "."]
    return "\n".join(lines) + "\n"
