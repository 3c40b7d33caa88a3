"""Prompt figures: do jump/hop prompts jump, and do walk/run prompts move at the corpus's speeds?

* Jumps (:func:`jump_summary`): per prompt and over all, the fraction of samples that jump
  (:func:`simdiff.eval.model_check.detect.jump_stats`) with a Wilson 95 % interval over samples
  (samples of one prompt are not fully independent; the per-prompt rows show the spread).
* Speeds (:func:`speed_summary`): quartiles of the samples' mean horizontal root speed per motion type and per
  prompt; per prompt, the quartiles of the corpus's *train* clips captioned with the prompt itself
  (:func:`captioned_speeds`, any length, originals only); per type, those of the train clips of that ``motion_type``
  and of about the samples' length (:func:`length_matched`; ``manifest.json``; mirrors left out: they have their
  original's speed) and of all lengths (no verdict). The verdicts (:mod:`~simdiff.eval.model_check.verdict`, session
  78) hold each prompt's sample median to its captioned clips' interquartile range; when fewer than five clips carry
  the caption, to that of the clips carrying any of its type's prompts; when those are fewer too, to the
  length-matched one. Why not length first, as in sessions 65-77: mocap runs are short because
  capture volumes are, and corpus3's 28 runs of about 6 s are all elderly or weary runs, while its clips captioned
  "a person runs forward." run 2.65 m/s (session 77). Beside them (no verdict): how many walk / run samples jump by
  the jump rule, against the corpus clips' rate over the samples' length (session 53: a model pushed to jump more
  can start hopping when asked to walk).

Both count the samples that never touch the floor (``never_touch``,
:func:`simdiff.motion.metrics.never_touches`); such a sample is not a jump.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.model_check.detect import MIN_FLIGHT_S, MIN_RISE_M, jump_stats, quartiles, root_speed, wilson
from simdiff.eval.model_check.samples import PromptBatch
from simdiff.eval.model_check.verdict import CAPTIONED_MIN
from simdiff.motion.metrics import FLOOR_CLEARANCE, never_touches

STANDING_LEVEL: str = ("median pelvis height over the frames outside every flight (feet on the ground by the "
                       "flight rule of simdiff/motion/flight.py)")


def _per_sample(batches: Sequence[PromptBatch]) -> list[PromptBatch]:
    return [b for b in batches for _ in range(b.count)]


def jump_summary(joints: np.ndarray, batches: Sequence[PromptBatch]) -> dict[str, Any]:
    """Jump fraction per prompt and overall over (N, T, 22, 3) samples generated from ``batches``."""
    owners = _per_sample(batches)
    if len(owners) != len(joints):
        raise SimdiffError(f"{len(joints)} motions for {len(owners)} planned samples")
    stats = [jump_stats(j) for j in joints]
    per_prompt = []
    for prompt in dict.fromkeys(b.prompt for b in batches):
        mine = [s for s, b in zip(stats, owners) if b.prompt == prompt]
        per_prompt.append(_row(prompt, mine))
    return {"rule": {"min_flight_s": MIN_FLIGHT_S, "min_rise_m": MIN_RISE_M, "standing_level": STANDING_LEVEL,
                     "floor": f"a sample whose lowest joint stays > {FLOOR_CLEARANCE:.2f} m above y = 0 in every "
                              "frame does not jump",
                     "interval": "Wilson 95 % over samples"},
            "per_prompt": per_prompt, "overall": _row("all", stats), "frames": int(joints.shape[1])}


def _row(prompt: str, stats: list[dict[str, Any]]) -> dict[str, Any]:
    k = sum(bool(s["jump"]) for s in stats)
    frac, lo, hi = wilson(k, len(stats))
    return {"prompt": prompt, "n": len(stats), "jumps": k, "fraction": frac, "wilson95": [lo, hi],
            "with_flight": sum(s["flight_s"] >= MIN_FLIGHT_S - 1e-9 for s in stats),
            "never_touch": sum(not s["touches_floor"] for s in stats),
            "median_flight_s": float(np.median([s["flight_s"] for s in stats])) if stats else float("nan"),
            "median_rise_m": float(np.median([s["rise_m"] for s in stats])) if stats else float("nan")}


LENGTH_WINDOW: float = 1.25
"""Corpus clips within [L / 1.25, L × 1.25] frames are compared with samples of L frames."""
MIN_MATCHED: int = 20
"""With fewer clips in the window, the 20 clips closest in length (log ratio) are used instead."""
SPEED_REFERENCE: dict[str, float | int] = {"speed_length_window": LENGTH_WINDOW, "speed_min_matched": MIN_MATCHED}
"""In the speeds section's fingerprint: the corpus reference is length-matched since session 65."""


def length_matched(frames: Sequence[int], length: int) -> list[int]:
    """Indices of the clips (``frames`` each) compared with samples of ``length`` frames: those within
    [length / :data:`LENGTH_WINDOW`, length × :data:`LENGTH_WINDOW`], or, when fewer than :data:`MIN_MATCHED` are,
    the :data:`MIN_MATCHED` closest in length by |log(frames / length)| (all clips when there are fewer)."""
    inside = [i for i, n in enumerate(frames) if length / LENGTH_WINDOW <= n <= length * LENGTH_WINDOW]
    if len(inside) >= MIN_MATCHED or len(frames) <= len(inside):
        return inside
    order = sorted(range(len(frames)), key=lambda i: (abs(np.log(max(frames[i], 1) / length)), i))
    return sorted(order[:MIN_MATCHED])


def corpus_clips(corpus: str | Path, types: Sequence[str], limit: int = 0, seed: int = 0,
                 frames: int = 0) -> dict[str, list[tuple[float, bool, int]]]:
    """(mean horizontal root speed m/s, jumps by :func:`jump_stats`, frames) of the corpus's train clips per
    ``motion_type`` (originals only); the jump rule reads each clip's first ``frames`` frames (0: all), the samples'
    length.

    Args:
        corpus: a corpus folder with ``manifest.json`` (``clips`` with ``id``, ``split``, ``motion_type``,
            ``mirror_of``) and ``new_joints/<id>.npy``.
        limit: at most this many clips per type, a seeded random subset (0: all).
    Raises:
        SimdiffError: no manifest, or a manifest without motion types.
    """
    clips = _train_originals(corpus)
    rng = np.random.default_rng(seed)
    out: dict[str, list[tuple[float, bool, int]]] = {}
    for kind in types:
        ids = sorted(c["id"] for c in clips if c["motion_type"] == kind)
        if limit and len(ids) > limit:
            ids = sorted(rng.choice(ids, limit, replace=False).tolist())
        rows = []
        for clip_id in ids:
            joints = _clip_joints(corpus, clip_id)
            rows.append((root_speed(joints), bool(jump_stats(joints[:frames] if frames else joints)["jump"]),
                         int(len(joints))))
        out[kind] = rows
    return out


def _caption_key(text: str) -> str:
    return text.strip().lower().rstrip(". ")


def captioned_speeds(corpus: str | Path, kinds: dict[str, Sequence[str]]) -> dict[str, list[float]]:
    """Per prompt: mean horizontal root speeds (m/s) of the corpus's train clips (originals) of the prompt's motion
    type any of whose captions is the prompt itself (case and the final full stop ignored), whatever their length;
    and per motion type (key ``"<type>:*"``), those of the clips captioned with any of the type's prompts, each clip
    once (the reference of a prompt too few clips carry, :data:`~simdiff.eval.model_check.verdict.CAPTIONED_MIN`).

    Raises:
        SimdiffError: as :func:`corpus_clips`.
    """
    wanted = {_caption_key(p): (kind, p) for kind, prompts in kinds.items() for p in prompts}
    out: dict[str, list[float]] = {p: [] for prompts in kinds.values() for p in prompts}
    out.update({pool_key(kind): [] for kind in kinds})
    for clip in _train_originals(corpus):
        keys = {_caption_key(c) for c in clip.get("captions", []) if isinstance(c, str)}
        hits = [wanted[k][1] for k in sorted(keys & wanted.keys()) if wanted[k][0] == clip["motion_type"]]
        if hits:
            speed = root_speed(_clip_joints(corpus, clip["id"]))
            for prompt in hits:
                out[prompt].append(speed)
            out[pool_key(clip["motion_type"])].append(speed)
    return out


def pool_key(kind: str) -> str:
    """:func:`captioned_speeds`' key for the clips captioned with any prompt of ``kind``."""
    return f"{kind}:*"


def _train_originals(corpus: str | Path) -> list[dict[str, Any]]:
    """The manifest's train clips that are not mirrors, each with a ``motion_type``."""
    path = Path(corpus) / "manifest.json"
    if not path.is_file():
        raise SimdiffError(f"{path}: missing (the speed check needs the corpus manifest with motion_type)")
    try:
        clips = json.loads(path.read_text(encoding="utf-8")).get("clips")
    except (json.JSONDecodeError, AttributeError) as exc:
        raise SimdiffError(f"{path}: not a corpus manifest ({exc})") from None
    if not isinstance(clips, list) or not all(isinstance(c, dict) and "motion_type" in c for c in clips):
        raise SimdiffError(f"{path}: clips without 'motion_type' (build the corpus with `simdiff data build`)")
    return [c for c in clips if c.get("split") == "train" and not c.get("mirror_of")]


def _clip_joints(corpus: str | Path, clip_id: str) -> np.ndarray:
    f = Path(corpus) / "new_joints" / f"{clip_id}.npy"
    if not f.is_file():
        raise SimdiffError(f"{f}: missing (listed in manifest.json)")
    return np.load(f)


def speed_summary(joints: np.ndarray, batches: Sequence[PromptBatch], kinds: dict[str, Sequence[str]],
                  corpus: dict[str, list[float]], corpus_jumps: dict[str, list[bool]] | None = None,
                  corpus_frames: dict[str, list[int]] | None = None,
                  captioned: dict[str, list[float]] | None = None) -> dict[str, Any]:
    """Per motion type: quartiles of the samples' speeds (and per prompt) against the corpus clips' (only those of
    about the samples' length, :func:`length_matched`, when ``corpus_frames`` gives the clips' lengths); how many
    samples jump (a walk or run that jumps is not what was asked; the corpus clips' rate beside it when given);
    per prompt, the quartiles of ``captioned`` (:func:`captioned_speeds`) when given (no verdict)."""
    owners = _per_sample(batches)
    length = int(joints.shape[1])
    speeds = [root_speed(j) for j in joints]
    jumping = [bool(jump_stats(j)["jump"]) for j in joints]
    floating = never_touches(joints)
    out: dict[str, Any] = {"speed": "mean horizontal pelvis speed over the motion (m/s)",
                           "rule": "pass when the samples' median lies in the corpus train clips' [Q1, Q3]",
                           "types": {}}
    if corpus_frames is not None:
        out["rule"] = (f"the type's median in [Q1, Q3] of the corpus train clips within "
                       f"[{length / LENGTH_WINDOW:.0f}, {length * LENGTH_WINDOW:.0f}] frames (samples: {length}; "
                       f"the {MIN_MATCHED} closest in length when fewer)")
    if captioned is not None:
        out["rule"] = ("each prompt's sample median in [Q1, Q3] of the corpus train clips captioned with it (at least "
                       f"{CAPTIONED_MIN}; else with any of its type's prompts; else " + out["rule"].removeprefix("the type's median ") + ")")
    for kind, prompts in kinds.items():
        mine = [v for v, b in zip(speeds, owners) if b.prompt in prompts]
        every = list(corpus.get(kind, []))
        lengths = None if corpus_frames is None else list(corpus_frames.get(kind, []))
        ref = quartiles(every if lengths is None else [every[i] for i in length_matched(lengths, length)])
        gen = quartiles(mine)
        out["types"][kind] = {
            "prompts": list(prompts), "samples": gen, "corpus_train": ref,
            **({} if lengths is None else {"corpus_train_all_lengths": quartiles(every)}),
            "per_prompt": {p: quartiles([v for v, b in zip(speeds, owners) if b.prompt == p]) for p in prompts},
            **({} if captioned is None else
               {"per_prompt_corpus_captioned": {p: quartiles(list(captioned.get(p, []))) for p in prompts},
                "corpus_captioned_any_prompt": quartiles(list(captioned.get(pool_key(kind), [])))}),
            "never_touch": int(sum(f for f, b in zip(floating, owners) if b.prompt in prompts)),
            "jumping": _jumping([k for k, b in zip(jumping, owners) if b.prompt in prompts],
                                None if corpus_jumps is None else corpus_jumps.get(kind, [])),
            "median_in_iqr": bool(ref["n"] > 0 and ref["q1"] <= gen["median"] <= ref["q3"]) if gen["n"] else False}
    return out


def _jumping(samples: list[bool], corpus: list[bool] | None) -> dict[str, Any]:
    """Samples that jump by the jump rule (with a Wilson 95 % interval) and the corpus clips' fraction."""
    k = sum(samples)
    frac, lo, hi = wilson(k, len(samples))
    return {"n": len(samples), "jumps": k, "fraction": frac, "wilson95": [lo, hi],
            "corpus_train_fraction": sum(corpus) / len(corpus) if corpus else None,
            "corpus_train_n": None if corpus is None else len(corpus)}
