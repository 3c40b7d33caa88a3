"""Editing and long motions, measured on real clips of the split and one timeline.

* **Re-play** (``simdiff edit MOTION --gravity G``): the split's original clips of ``editing.replay_type`` that
  have a readable flight, re-played at Earth and at each gravity of ``editing.gravity``; per motion the gravity
  read from the flights (:mod:`simdiff.motion.gravity_readout`), airborne frames and apex against the input's, and
  the mean joint displacement (at Earth: how far the input comes back).
* **Keyframes** (``generate --keyframes``): the first ``editing.keyframe_frames`` frames of the split's clips of
  ``editing.keyframe_type``, with their first caption, as an in-between (first and last pose), a continuation (the
  first 20 frames), a root path (x/z every 20 frames) and a pinned pose (the middle one); per motion the largest
  distance of a written joint from its entry and the fastest joint within 5 frames of a given frame against the
  fastest of the same caption and seed without keyframes.
* **Keep** (``simdiff edit --keep lower|upper --text``): the same clips with one half kept and the other made for
  ``editing.keep``'s text; per motion the largest and mean distance of a kept joint from the input, and what the new
  half does: the right wrist's share of frames above the head (legs kept, a wave asked) or the right ankle's lift
  above its floor (upper body kept, a kick asked), each against the input's.
* **Timeline** (``generate --timeline``): ``editing.timeline``'s segments as one motion; per segment its pelvis
  speed, travel, apex, airborne frames and gravity read, and the right wrist's share of frames above the head; per
  seam the fastest joint and the root's largest acceleration within 5 frames, against the whole motion's 99th
  percentile.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.experiments.clips import split_clips
from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.runner import RowPlan, Runner, safe
from simdiff.eval.stats import t_interval
from simdiff.fsio import save_npy
from simdiff.motion.skeleton import FPS

TITLE = "Editing and long motions — re-play under φ, keyframes, timelines"
KEYFRAME_CASES: tuple[str, ...] = ("in-between", "continuation", "path", "pinned")
NEAR_FRAMES: int = 5
"""Frames either side of a given frame (or a seam) in which joint speeds are compared."""


def _interval(values: list[float]) -> dict[str, float]:
    mean, half = t_interval(np.asarray(values, dtype=np.float64))
    return {"mean": mean, "ci95": half if half == half else 0.0, "n": len(values)}


def _fastest(joints: np.ndarray, frames: np.ndarray | None = None) -> float:
    """Fastest joint (m/s), over all frames or within :data:`NEAR_FRAMES` of ``frames``."""
    speed = np.linalg.norm(np.diff(joints, axis=0), axis=-1).max(axis=-1) * FPS  # (T-1,)
    if frames is None:
        return float(speed.max())
    near = np.zeros(len(speed), dtype=bool)
    for f in frames:
        near[max(0, f - NEAR_FRAMES): f + NEAR_FRAMES] = True
    return float(speed[near].max())


def measure_replay(runner: Runner, spec: ModelSpec, gravity: float, key: str) -> dict[str, Any]:
    from simdiff.inference.editing import edit_motion
    from simdiff.motion.gravity_readout import read_gravity

    o = runner.config.editing
    gen = runner.model(spec)
    sampling = runner.sampling(spec, "ddim", runner.alpha(spec))
    per = []
    for i, clip in enumerate(split_clips(runner, o.replay_type, o.replay_clips, flight=True)):
        for s in range(o.seeds):
            edited = edit_motion(gen, clip["joints"], sampling, (gravity, 0.0, 0.0), seed=runner.config.seed + s)
            before, after = read_gravity(clip["joints"]), read_gravity(edited.joints)
            per.append({"clip": clip["id"], "changed_m": edited.changed_m,
                        "gravity_read": None if after is None else after["gravity"],
                        "fit_mm": None if after is None else 1000 * after["rmse_m"],
                        "airborne": 0.0 if after is None else after["frames"], "airborne_input": before["frames"],
                        "apex_gain_m": float(edited.joints[:, 0, 1].max() - clip["joints"][:, 0, 1].max())})
            if i == 0 and s == 0:
                save_npy(runner.rows_dir / f"{key}.motion.npy", edited.joints)
    read = [p["gravity_read"] for p in per if p["gravity_read"] is not None]
    return {"clips": sorted({p["clip"] for p in per}), "motions": per,
            "gravity_read": _interval(read) if read else {"n": 0},
            "within_25pct": float(np.mean([abs(g - gravity) <= 0.25 * abs(gravity) for g in read])) if read else 0.0,
            "longer_and_higher": float(np.mean([p["airborne"] > p["airborne_input"] and p["apex_gain_m"] > 0
                                                for p in per])),
            "changed_m": _interval([p["changed_m"] for p in per])}


def keyframes_of(joints: np.ndarray, case: str) -> np.ndarray:
    """The keyframes (T, 22, 3, NaN = free) of ``case`` (:data:`KEYFRAME_CASES`) taken from ``joints``."""
    keys = np.full_like(joints, np.nan)
    if case == "in-between":
        keys[0], keys[-1] = joints[0], joints[-1]
    elif case == "continuation":
        keys[:20] = joints[:20]
    elif case == "path":
        keys[::20, 0, 0], keys[::20, 0, 2] = joints[::20, 0, 0], joints[::20, 0, 2]
    elif case == "pinned":
        keys[len(joints) // 2] = joints[len(joints) // 2]
    else:
        raise SimdiffError(f"unknown keyframe case {case!r}; choose from {', '.join(KEYFRAME_CASES)}")
    return keys


def measure_keyframes(runner: Runner, spec: ModelSpec, case: str, key: str) -> dict[str, Any]:
    from simdiff.inference.keyframes import keyframe_error, sample_keyframed
    from simdiff.motion.rigid import joints_from_features

    o = runner.config.editing
    gen = runner.model(spec)
    sampling = runner.sampling(spec, "ddim", runner.alpha(spec))
    env = (-9.81, 0.0, 0.0) if gen.is_simdiff else None
    per = []
    for i, clip in enumerate(split_clips(runner, o.keyframe_type, o.keyframe_clips, min_frames=o.keyframe_frames)):
        real = clip["joints"][: o.keyframe_frames]
        keys = keyframes_of(real, case)
        text = gen.encode_text([clip["caption"]])
        _, joints = sample_keyframed(gen, keys, sampling, text_embeddings=text, env=env, seed=runner.config.seed)
        free = gen.generate([clip["caption"]], len(real), sampling, env=env, seed=runner.config.seed,
                            text_embeddings=text)
        free_joints = joints_from_features(free.clips()[0].cpu().numpy(), sampling.foot_lock)
        frames = np.flatnonzero(np.isfinite(keys).any(axis=(1, 2)))
        per.append({"clip": clip["id"], "max_error_cm": 100 * keyframe_error(joints, keys),
                    "fastest_near": _fastest(joints, frames), "fastest": _fastest(joints),
                    "fastest_free": _fastest(free_joints)})
        if i == 0:
            save_npy(runner.rows_dir / f"{key}.motion.npy", joints)
    return {"clips": [p["clip"] for p in per], "motions": per,
            **{k: _interval([p[k] for p in per]) for k in ("max_error_cm", "fastest_near", "fastest", "fastest_free")},
            "worst_error_cm": max(p["max_error_cm"] for p in per)}


def _wrist_up(joints: np.ndarray) -> float:
    """Share of frames with the right wrist above the head."""
    return float((joints[:, 21, 1] > joints[:, 15, 1]).mean())


def _ankle_lift(joints: np.ndarray) -> float:
    """The right ankle's highest point above its floor (its 5th-percentile height), m."""
    return float(joints[:, 8, 1].max() - np.percentile(joints[:, 8, 1], 5))


def measure_keep(runner: Runner, spec: ModelSpec, key: str) -> dict[str, Any]:
    from simdiff.inference.editing import keep_half
    from simdiff.motion.skeleton import LOWER_BODY, UPPER_BODY

    o = runner.config.editing
    gen = runner.model(spec)
    sampling = runner.sampling(spec, "ddim", runner.alpha(spec))
    env = (-9.81, 0.0, 0.0) if gen.is_simdiff else None
    per, shown = [], []
    for i, clip in enumerate(split_clips(runner, o.keyframe_type, o.keyframe_clips, min_frames=o.keyframe_frames)):
        real = clip["joints"][: o.keyframe_frames]
        for half, text in sorted(o.keep.items()):
            joints = keep_half(gen, real, sampling, env, half, text, seed=runner.config.seed).joints
            kept = list(LOWER_BODY if half == "lower" else UPPER_BODY)
            error = 100 * np.linalg.norm(joints[:, kept] - real[:, kept], axis=-1)
            measure = _wrist_up if half == "lower" else _ankle_lift
            per.append({"clip": clip["id"], "half": half, "text": text, "max_error_cm": float(error.max()),
                        "mean_error_cm": float(error.mean()), "new_half": measure(joints), "input": measure(real)})
            if i == 0:
                shown.append(joints)
    save_npy(runner.rows_dir / f"{key}.motion.npy", np.stack(shown))
    halves = {}
    for half, text in sorted(o.keep.items()):
        mine = [p for p in per if p["half"] == half]
        halves[half] = {"text": text, "worst_error_cm": max(p["max_error_cm"] for p in mine),
                        **{k: _interval([p[k] for p in mine]) for k in ("max_error_cm", "mean_error_cm", "new_half",
                                                                         "input")}}
    return {"clips": sorted({p["clip"] for p in per}), "motions": per, "halves": halves}


def timeline_segments(timeline: list[dict[str, Any]]) -> tuple[Any, ...]:
    """The config's segments ``{"text", "seconds", "gravity"?, "wind"?}`` as
    :class:`~simdiff.inference.timeline.Segment` (φ checked against the trained range)."""
    from simdiff.inference.timeline import Segment
    from simdiff.sim.env import EARTH_GRAVITY, Environment

    try:
        return tuple(Segment(str(s["text"]), int(round(float(s["seconds"]) * FPS)),
                             Environment(float(s.get("gravity", EARTH_GRAVITY)),
                                         *(float(w) for w in s.get("wind", [0.0, 0.0]))).validate())
                     for s in timeline)
    except (KeyError, TypeError, ValueError) as exc:
        raise SimdiffError(f"editing.timeline: each segment needs text and seconds, optional gravity and wind [x, y] "
                           f"({type(exc).__name__}: {exc})") from None


def measure_timeline(runner: Runner, spec: ModelSpec, key: str) -> dict[str, Any]:
    from simdiff.inference.timeline import sample_timeline, spans
    from simdiff.motion.gravity_readout import read_gravity

    segments = timeline_segments(runner.config.editing.timeline)
    gen = runner.model(spec)
    sampling = runner.sampling(spec, "ddim", runner.alpha(spec))
    _, joints = sample_timeline(gen, segments, sampling, seed=runner.config.seed)
    save_npy(runner.rows_dir / f"{key}.motion.npy", joints)
    root = np.linalg.norm(np.diff(joints[:, 0, [0, 2]], axis=0), axis=-1) * FPS
    acc = np.linalg.norm(np.diff(joints[:, 0], 2, axis=0), axis=-1) * FPS**2
    parts = []
    for seg, (a, b) in zip(segments, spans(segments)):
        piece, g = joints[a:b], read_gravity(joints[a:b])
        parts.append({"text": seg.text, "env": list(seg.env.as_tuple()), "frames": [a, b],
                      "pelvis_speed": float(root[a: b - 1].mean()),
                      "travel_m": float(np.linalg.norm(piece[-1, 0, [0, 2]] - piece[0, 0, [0, 2]])),
                      "apex_m": float(piece[:, 0, 1].max()), "airborne": 0.0 if g is None else g["frames"],
                      "gravity_read": None if g is None else g["gravity"],
                      "wrist_above_head": _wrist_up(piece)})
    seams = [{"frame": a, "fastest": _fastest(joints, np.array([a])),
              "root_acc_max": float(acc[max(0, a - NEAR_FRAMES): a + NEAR_FRAMES].max())}
             for a, _ in spans(segments)[1:]]
    return {"frames": int(len(joints)), "segments": parts, "seams": seams,
            "root_acc_p99": float(np.percentile(acc, 99)), "fastest": _fastest(joints)}


def plan(runner: Runner) -> list[RowPlan]:
    c, o = runner.config, runner.config.editing
    if o.seeds < 1 or o.replay_clips < 1 or o.keyframe_clips < 1:
        raise SimdiffError("editing needs seeds, replay_clips and keyframe_clips >= 1")
    plans = []
    for spec in c.models:
        alpha = runner.alpha(spec)
        base = {**runner.method_inputs(spec, "ddim", alpha), **runner.data_inputs()}
        for g in [-9.81, *o.gravity]:
            key = safe(f"{spec.name}_replay_g{g:g}")
            inputs = {"row": "editing_replay", "gravity": g, "type": o.replay_type, "clips": o.replay_clips,
                      "seeds": o.seeds, **base}
            plans.append(RowPlan(key, {"method": spec.name, "part": "replay", "gravity": g}, inputs,
                                 runner.motion_seconds(spec, "ddim", 2 * o.replay_clips * o.seeds),
                                 lambda r, spec=spec, g=g, key=key: measure_replay(r, spec, g, key)))
        for case in KEYFRAME_CASES:
            key = safe(f"{spec.name}_keyframes_{case}")
            inputs = {"row": "editing_keyframes", "case": case, "type": o.keyframe_type, "clips": o.keyframe_clips,
                      "frames": o.keyframe_frames, **base}
            plans.append(RowPlan(key, {"method": spec.name, "part": "keyframes", "case": case}, inputs,
                                 runner.motion_seconds(spec, "ddim", 2 * o.keyframe_clips),
                                 lambda r, spec=spec, case=case, key=key: measure_keyframes(r, spec, case, key)))
        if o.keep:
            key = safe(f"{spec.name}_keep")
            inputs = {"row": "editing_keep", "keep": o.keep, "type": o.keyframe_type, "clips": o.keyframe_clips,
                      "frames": o.keyframe_frames, **base}
            plans.append(RowPlan(key, {"method": spec.name, "part": "keep"}, inputs,
                                 runner.motion_seconds(spec, "ddim", 2 * o.keyframe_clips * len(o.keep)),
                                 lambda r, spec=spec, key=key: measure_keep(r, spec, key)))
        if o.timeline:
            key = safe(f"{spec.name}_timeline")
            inputs = {"row": "editing_timeline", "timeline": o.timeline, **base}
            plans.append(RowPlan(key, {"method": spec.name, "part": "timeline"}, inputs,
                                 runner.motion_seconds(spec, "ddim", len(o.timeline)),
                                 lambda r, spec=spec, key=key: measure_timeline(r, spec, key)))
    return plans


def _ci(s: dict[str, Any], fmt: str = ".2f") -> str:
    return f"{s['mean']:{fmt}} ± {s['ci95']:{fmt}}" if s.get("n") else "—"


def _figures(runner: Runner, rows: list[dict[str, Any]]) -> list[Path]:
    """Filmstrips: the first re-played clip at Earth's input and each gravity, the first keyframe clip's cases,
    the timeline."""
    from simdiff.viz.stick import render_filmstrip

    def motion(row: dict[str, Any]) -> np.ndarray | None:
        f = runner.rows_dir / f"{row['key']}.motion.npy"
        return np.load(f) if f.is_file() else None

    o = runner.config.editing
    paths = []
    replay = [r for r in rows if r["part"] == "replay" and motion(r) is not None]
    if replay:
        clip = split_clips(runner, o.replay_type, 1, flight=True)[0]
        path = runner.out / "editing_replay.png"
        render_filmstrip([clip["joints"]] + [motion(r) for r in replay], path,
                         [f"input {clip['id']}"] + [f"re-played at g {r['gravity']:g}" for r in replay])
        paths.append(path)
    keyed = [r for r in rows if r["part"] == "keyframes" and motion(r) is not None]
    kept = [(f"keep {half}: \"{h['text']}\"", m) for r in rows if r["part"] == "keep" and motion(r) is not None
            for (half, h), m in zip(sorted(r["halves"].items()), motion(r))]
    if keyed or kept:
        clip = split_clips(runner, o.keyframe_type, 1, min_frames=o.keyframe_frames)[0]
        path = runner.out / "editing_keyframes.png"
        render_filmstrip([clip["joints"][: o.keyframe_frames]] + [motion(r) for r in keyed] + [m for _, m in kept],
                         path, [f"real {clip['id']}: \"{clip['caption']}\""] + [r["case"] for r in keyed]
                         + [label for label, _ in kept])
        paths.append(path)
    for r in rows:
        if r["part"] == "timeline" and motion(r) is not None:
            path = runner.out / "editing_timeline.png"
            render_filmstrip([motion(r)], path, [" → ".join(s["text"] for s in r["segments"])], n_frames=10)
            paths.append(path)
    return paths


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    o = runner.config.editing
    rows = report["rows"]
    lines = [f"Re-play: the {runner.config.split} split's original {o.replay_type} clips with a readable flight "
             f"(first {o.replay_clips}), {o.seeds} seed(s) each, re-played with `simdiff edit`. g read: gravity of the "
             "centre of mass's parabola over the flights (m/s², mean ± 95% CI over motions with a flight, their count "
             "in brackets); within 25 %: share of those readings within 25 % of the requested g; longer and higher: "
             "share of motions whose flights last more frames and whose apex is higher than the input's; moved: mean "
             "joint displacement from the input (m).", "",
             "| method | g | g read (m/s²) | within 25 % | longer and higher | moved (m) |", "|---|---|---|---|---|---|"]
    for r in (r for r in rows if r["part"] == "replay"):
        g = r["gravity_read"]
        lines.append(f"| {r['method']} | {r['gravity']:g} | {_ci(g)} [{g['n']}] | {r['within_25pct']:.0%} | "
                     f"{r['longer_and_higher']:.0%} | {_ci(r['changed_m'], '.3f')} |")
    lines += ["", f"Keyframes: the first {o.keyframe_frames} frames of the split's first {o.keyframe_clips} "
              f"{o.keyframe_type} clips with their first caption. Error: the largest distance of a written joint from "
              f"its entry (cm); fastest joint (m/s) within {NEAR_FRAMES} frames of a given frame, over the motion, and "
              "over the same caption and seed generated without keyframes.", "",
              "| method | case | error (cm) | worst (cm) | fastest near keys | fastest | fastest without keys |",
              "|---|---|---|---|---|---|---|"]
    for r in (r for r in rows if r["part"] == "keyframes"):
        lines.append(f"| {r['method']} | {r['case']} | {_ci(r['max_error_cm'])} | {r['worst_error_cm']:.2f} | "
                     f"{_ci(r['fastest_near'], '.1f')} | {_ci(r['fastest'], '.1f')} | {_ci(r['fastest_free'], '.1f')} |")
    for r in (r for r in rows if r["part"] == "keep"):
        lines += ["", ("Keep: `simdiff edit --keep` on the same clips, one half kept and the other made for the text. "
                       "Kept error: distance of a kept joint from the input (cm; each motion's largest, its mean, and "
                       "the worst); new half: the right wrist's share of frames above the head when the legs are "
                       "kept, the right ankle's lift above its floor (m) when the upper body is kept, against the "
                       "input's."), "",
                  "| method | kept | text | kept error (cm) | mean (cm) | worst (cm) | new half | input |",
                  "|---|---|---|---|---|---|---|---|"]
        for half, h in sorted(r["halves"].items()):
            fmt = ".0%" if half == "lower" else ".2f"
            new, old = h["new_half"], h["input"]
            lines.append(f"| {r['method']} | {half} | {h['text']} | {_ci(h['max_error_cm'])} | "
                         f"{_ci(h['mean_error_cm'])} | {h['worst_error_cm']:.2f} | "
                         f"{new['mean']:{fmt}} ± {new['ci95']:{fmt}} | {old['mean']:{fmt}} ± {old['ci95']:{fmt}} |")
    for r in (r for r in rows if r["part"] == "timeline"):
        lines += ["", f"Timeline ({r['method']}, {r['frames']} frames, {r['frames'] / FPS:g} s): per segment; the "
                  "whole motion's fastest joint {:.1f} m/s, root acceleration p99 {:.1f} m/s².".format(
                      r["fastest"], r["root_acc_p99"]), "",
                  "| segment | φ | frames | pelvis (m/s) | travel (m) | apex (m) | airborne | g read | wrist above head |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for s in r["segments"]:
            g = "—" if s["gravity_read"] is None else f"{s['gravity_read']:.2f}"
            lines.append(f"| {s['text']} | {tuple(round(v, 2) for v in s['env'])} | {s['frames'][0]}–{s['frames'][1]} | "
                         f"{s['pelvis_speed']:.2f} | {s['travel_m']:.1f} | {s['apex_m']:.2f} | {s['airborne']:.0f} | "
                         f"{g} | {s['wrist_above_head']:.0%} |")
        lines += ["", "| seam at frame | fastest joint ±5 frames (m/s) | root acceleration max ±5 frames (m/s²) |",
                  "|---|---|---|"]
        lines += [f"| {s['frame']} | {s['fastest']:.1f} | {s['root_acc_max']:.1f} |" for s in r["seams"]]
    lines += [""] + [f"![{p.stem}]({p.name})" for p in _figures(runner, rows)]
    return lines
