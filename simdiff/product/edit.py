"""``simdiff edit``'s run: the edit of a user's motion (:mod:`simdiff.inference.editing`) written as one set."""

from __future__ import annotations

import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.inference.editing import edit_motion, keep_half
from simdiff.motion.skeleton import FPS
from simdiff.product.outputs import (
    prepare_out_dir,
    render_video,
    write_metadata,
    write_motion,
)

if TYPE_CHECKING:
    from simdiff.sim.env import Environment

@dataclass(frozen=True)
class EditRequest:
    """One checked ``simdiff edit`` run.

    Attributes:
        source: the motion file; joints: its (T, 22, 3) joints, metres, Y up, 20 fps.
        env: φ to re-play under (or to make the new half under).
        formats: output kinds (:data:`simdiff.product.request.FORMATS`).
        text: what the motion shows (optional for a re-play; the new half's prompt with ``keep``).
        seed: noise seed.
        keep: None (re-play under φ) or the half kept (:data:`HALVES`).
    """

    source: Path
    joints: np.ndarray
    env: Environment
    formats: Sequence[str]
    text: str = ""
    seed: int = 0
    keep: str | None = None


def _continuous(generator) -> bool:
    return generator.config.sim is not None and generator.config.sim.mode == "continuous"


def check_replay_model(generator, folder: Path) -> None:
    """Refuse a model (a :class:`~simdiff.inference.generator.MotionGenerator` loaded from ``folder``) without φ as
    numbers: it cannot re-play a motion under gravity and wind."""
    if not _continuous(generator):
        raise SimdiffError(f"{folder} has no continuous environment input (φ as numbers); it cannot re-play a "
                           "motion under gravity and wind")


def gravity_readings(before: np.ndarray, after: np.ndarray) -> dict[str, dict[str, float] | None]:
    """``{input, edited}``: the gravity read from the flights of the input and the edited joints (T, 22, 3)
    (:func:`simdiff.motion.gravity_readout.read_gravity`; None where no flight is readable)."""
    from simdiff.motion.gravity_readout import read_gravity

    return {"input": read_gravity(before), "edited": read_gravity(after)}


def edit_file(request: EditRequest, out_dir: Path, *, model: Path | None = None, device: str = "cpu",
              quiet: bool = False) -> tuple[list[Path], str]:
    """Run ``request`` with the default (or given) model and write the edit, a side-by-side video and ``edit.json``
    into ``out_dir``; (written paths, a one-line summary). A failed run leaves no folder it created behind. A
    progress bar on stderr unless ``quiet``."""
    from simdiff.inference.default import check_model_dir

    folder = check_model_dir(model)
    created = not out_dir.exists()
    try:
        return _edit_into(request, prepare_out_dir(out_dir), folder, model, device, quiet)
    except BaseException:
        if created:
            shutil.rmtree(out_dir, ignore_errors=True)
        raise


def _edit_into(request: EditRequest, out_dir: Path, folder: Path, model: Path | None, device: str,
               quiet: bool) -> tuple[list[Path], str]:
    """:func:`edit_file` once the output folder exists."""
    import time

    from simdiff.fsio import check_writable, output_set
    from simdiff.inference.default import load_default, sampling_config
    from simdiff.inference.device import torch_device
    from simdiff.product.pipeline import describe_env

    check_writable(out_dir / "edit.json")  # a read-only folder fails now, not after sampling
    start = time.perf_counter()
    joints, env = request.joints, request.env
    generator = load_default(model, torch_device(device), load_text=bool(request.text))
    if request.keep is None:
        check_replay_model(generator, folder)
    elif generator.is_simdiff and not _continuous(generator):
        raise SimdiffError(f"{folder} has categorical environments; use a model with φ as numbers")
    config = sampling_config(model)
    loaded = time.perf_counter()
    if request.keep is None:
        import sys

        from tqdm.auto import tqdm

        from simdiff.inference.replay import replay_step_count

        with tqdm(total=replay_step_count(config, len(joints) - 1), desc="re-playing", unit="step", leave=False,
                  disable=quiet, file=sys.stderr, dynamic_ncols=True) as bar:

            def progress(ts):
                for t in ts:
                    yield t
                    bar.update(1)

            edited = edit_motion(generator, joints, config, env.as_tuple(), seed=request.seed, text=request.text,
                                 progress=progress)
    else:
        edited = keep_half(generator, joints, config, env.as_tuple() if generator.is_simdiff else None, request.keep,
                           request.text, seed=request.seed)
    sampled = time.perf_counter()
    label = describe_env(env) if request.keep is None else f"{request.keep} body kept: {request.text}"
    with output_set(out_dir, last="edit.json") as stage:  # every file appears together, or none
        written = write_motion(stage / "edited", edited.joints, edited.features, request.formats)
        paths = list(written.values())
        for kind in ("gif", "mp4"):
            if kind in request.formats:
                paths.append(render_video([joints.astype(np.float32), edited.joints], ["input", label],
                                          stage / f"compare.{kind}"))
        meta = {
            "input": str(request.source), "frames": int(joints.shape[0]), "fps": FPS,
            "environment": {"gravity": env.gravity, "wind": [env.wind_x, env.wind_y]},
            "keep": request.keep, "text": request.text, "seed": request.seed, "sampling": config.to_dict(),
            "model": str(folder), "changed_m": round(edited.changed_m, 4),
            "gravity_read": gravity_readings(joints, edited.joints),
            "files": sorted(p.name for p in paths),
            "seconds": {"load_model": round(loaded - start, 3), "sample": round(sampled - loaded, 3),
                        "write": round(time.perf_counter() - sampled, 3)},
        }
        paths.append(write_metadata(stage / "edit.json", meta))
    paths = [out_dir / p.name for p in paths]
    what = "re-played under " + describe_env(env) if request.keep is None else f"with the {request.keep} body kept"
    return paths, f"{joints.shape[0]} frames {what}; joints moved {100 * edited.changed_m:.1f} cm on average"
