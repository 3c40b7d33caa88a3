"""Contacts and speeds of the written joints, per motion type, against real mocap of that type.

For each motion type in ``contacts.prompts`` (walk, run, jump, ...) every model generates every caption × seed at
Earth gravity without wind, once; each motion is decoded twice: without the foot cleanup (``foot_lock`` 0: the
features as sampled, smoothed and fitted on a rigid skeleton) and with it (the model's ``foot_lock``: swing feet
lifted, a floating clip dropped, planted feet held by leg IK), exactly as ``simdiff generate`` writes them. The
corpus's original clips of that type in the split are the real reference. Per group:

* sliding (mm/frame) and skate ratio: :mod:`simdiff.motion.metrics` (CLoSD's lowest-joint sliding, GMD's
  skate ratio) per motion, mean ± 95% CI over motions;
* fastest joint (m/s) per motion, and the share of motions above the corpus's fastest joint for that type (all
  splits, originals);
* the root's 99th-percentile acceleration (m/s²) per motion and the share of motions with a one-frame root jump
  (root acceleration above the corpus's largest for that type);
* the largest per-motion standard deviation of a bone's length (mm).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.runner import EARTH, RowPlan, Runner, safe
from simdiff.eval.stats import t_interval
from simdiff.motion.skeleton import FPS

TITLE = "Contacts and speeds per motion type — written joints against real mocap"
PER_MOTION = ("max_speed", "root_acc_p99", "bone_std_mm")


def motion_measures(joints: np.ndarray) -> dict[str, float]:
    """(T, 22, 3) joints → fastest joint (m/s), root acceleration's 99th percentile and maximum (m/s²), largest
    bone-length standard deviation (mm)."""
    from simdiff.motion.rigid import bone_lengths

    joints = np.asarray(joints, dtype=np.float64)
    speed = np.linalg.norm(np.diff(joints, axis=0), axis=-1) * FPS
    acc = np.linalg.norm(np.diff(joints[:, 0], 2, axis=0), axis=-1) * FPS**2
    return {"max_speed": float(speed.max()), "root_acc_p99": float(np.percentile(acc, 99)) if acc.size else 0.0,
            "root_acc_max": float(acc.max()) if acc.size else 0.0,
            "bone_std_mm": float(bone_lengths(joints).std(axis=0).max() * 1000.0)}


def corpus_clips(runner: Runner, kind: str, split: str | None) -> list[np.ndarray]:
    """Joints of the corpus's original clips of motion type ``kind`` (in ``split``; None: all splits)."""
    corpus = Path(runner.config.corpus).expanduser()
    manifest = json.loads((corpus / "manifest.json").read_text(encoding="utf-8"))
    ids = [c["id"] for c in manifest["clips"]
           if c.get("motion_type") == kind and not c.get("mirror_of") and (split is None or c.get("split") == split)]
    return [np.load(corpus / "new_joints" / f"{i}.npy", allow_pickle=False) for i in ids]


def limits(runner: Runner, kind: str) -> dict[str, float]:
    """The corpus's fastest joint and largest root acceleration for motion type ``kind`` (all splits)."""
    stats = [motion_measures(j) for j in corpus_clips(runner, kind, None)]
    if not stats:
        raise SimdiffError(f"the corpus has no clips of motion type {kind!r}")
    return {"max_speed": max(s["max_speed"] for s in stats), "root_acc_max": max(s["root_acc_max"] for s in stats)}


def summarise(motions: list[np.ndarray], limit: dict[str, float]) -> dict[str, Any]:
    """Group statistics of ``motions`` (see the module docstring)."""
    from simdiff.motion.metrics import per_sample_physics_metrics

    frames = max(len(m) for m in motions)
    per = [motion_measures(m) for m in motions]
    out: dict[str, Any] = {"n": len(motions)}
    padded = np.stack([np.concatenate([m, np.repeat(m[-1:], frames - len(m), axis=0)]) for m in motions])
    physics = per_sample_physics_metrics(padded, [len(m) for m in motions])
    for key in ("sliding", "skate_ratio"):
        mean, half = t_interval(np.asarray(physics[key], dtype=np.float64))
        out[key] = {"mean": mean, "ci95": half if half == half else 0.0}
    for key in PER_MOTION:
        v = np.array([p[key] for p in per])
        out[key] = {"median": float(np.median(v)), "max": float(v.max())}
    out["above_speed_limit"] = float(np.mean([p["max_speed"] > limit["max_speed"] for p in per]))
    out["root_jumps"] = float(np.mean([p["root_acc_max"] > limit["root_acc_max"] for p in per]))
    return out


def measure_real(runner: Runner, kind: str) -> dict[str, Any]:
    clips = corpus_clips(runner, kind, runner.config.split)
    if not clips:
        raise SimdiffError(f"the {runner.config.split} split has no clips of motion type {kind!r}")
    limit = limits(runner, kind)
    return {"limits": limit, "real": summarise(clips, limit)}


def measure_model(runner: Runner, spec: ModelSpec, kind: str) -> dict[str, Any]:
    """Generate the type's captions × seeds once; summarise both decodes."""
    from simdiff.eval.protocol import generator_fn
    from simdiff.motion.foot_lock import clean_feet
    from simdiff.motion.rigid import joints_from_features

    o = runner.config.contacts
    captions = [p for p in o.prompts[kind] for _ in range(o.seeds)]
    gen = runner.model(spec)
    sampling = runner.sampling(spec, "ddim", runner.alpha(spec) if runner.is_simdiff(spec) else None)
    env = list(EARTH) if gen.is_simdiff and gen.config.sim.mode == "continuous" else None
    fn = generator_fn(gen, sampling.updated(foot_lock=0.0), env=env)
    feats, seconds = runner.generate(fn, captions, [o.length] * len(captions), runner.config.seed)
    limit = limits(runner, kind)
    raw = feats.double().numpy()
    cleaned = clean_feet(feats.double(), strength=sampling.foot_lock).numpy() if sampling.foot_lock else raw
    return {"foot_lock": sampling.foot_lock, "s_per_motion": seconds / len(captions),
            "without": summarise([joints_from_features(f) for f in raw], limit),
            "with": summarise([joints_from_features(f, sampling.foot_lock) for f in cleaned], limit)}


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    o = c.contacts
    if not o.prompts or o.seeds < 1:
        raise SimdiffError("contacts needs 'contacts.prompts' (motion type → captions) and 'contacts.seeds' >= 1")
    plans = []
    for kind in o.prompts:
        plans.append(RowPlan(safe(f"real_{kind}"), {"method": "real mocap", "type": kind},
                             {"row": "contacts_real", "type": kind, **runner.data_inputs()}, 5.0,
                             lambda r, kind=kind: measure_real(r, kind)))
        for spec in c.models:
            n = len(o.prompts[kind]) * o.seeds
            alpha = runner.alpha(spec) if runner.is_simdiff(spec) else None
            inputs = {"row": "contacts", "type": kind, **runner.method_inputs(spec, "ddim", alpha, EARTH),
                      "prompts": o.prompts[kind], "seeds": o.seeds, "length": o.length, "seed": c.seed}
            plans.append(RowPlan(safe(f"{spec.name}_{kind}"), {"method": spec.name, "type": kind}, inputs,
                                 runner.motion_seconds(spec, "ddim", n),
                                 lambda r, spec=spec, kind=kind: measure_model(r, spec, kind)))
    return plans


def _cells(s: dict[str, Any]) -> list[str]:
    return [f"{s['sliding']['mean']:.3f} ± {s['sliding']['ci95']:.3f}",
            f"{s['skate_ratio']['mean']:.3f} ± {s['skate_ratio']['ci95']:.3f}",
            f"{s['max_speed']['median']:.1f} / {s['max_speed']['max']:.1f}", f"{s['above_speed_limit']:.0%}",
            f"{s['root_acc_p99']['median']:.1f} / {s['root_acc_p99']['max']:.1f}", f"{s['root_jumps']:.0%}",
            f"{s['bone_std_mm']['max']:.2f}", str(s["n"])]


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    rows = report["rows"]
    lines = ["Written joints at Earth gravity, no wind. Sliding: mm/frame (CLoSD), skate ratio (GMD), mean ± 95% CI; "
             "fastest joint and root acceleration p99: median / max over motions; \"above\": share of motions with "
             "a joint faster than the corpus's fastest for the type; \"root jumps\": share with a root acceleration "
             "above the corpus's largest for the type; bone σ: the largest per-motion standard deviation of a "
             "bone's length.", "",
             "| type | motions | sliding | skate ratio | fastest joint (m/s) | above | root acc p99 (m/s²) | root jumps "
             "| bone σ (mm) | n |", "|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        if row["method"] == "real mocap":
            lim = row["limits"]
            lines.append(f"| {row['type']} | real ({runner.config.split}; corpus max {lim['max_speed']:.1f} m/s, "
                         f"{lim['root_acc_max']:.0f} m/s²) | " + " | ".join(_cells(row["real"])) + " |")
        else:
            for decode in ("without", "with"):
                label = f"{row['method']}, {'no cleanup' if decode == 'without' else 'foot_lock ' + format(row['foot_lock'], 'g')}"
                lines.append(f"| {row['type']} | {label} | " + " | ".join(_cells(row[decode])) + " |")
    prompts = runner.config.contacts.prompts
    lines += ["", "Captions: " + "; ".join(f"{k}: " + ", ".join(f"\"{p}\"" for p in v) for k, v in prompts.items()),
              f"({runner.config.contacts.seeds} seeds each, {runner.config.contacts.length} frames)."]
    return lines
