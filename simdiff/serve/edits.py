"""The viewer's work on motions it has shown: a generation that starts or ends in a shown motion's pose (pins), a
shown motion re-played under φ (``POST /api/edit``) and a timeline of prompts (``POST /api/timeline``).

Each runs the product's own code (:func:`simdiff.inference.keyframes.sample_keyframed`,
:func:`simdiff.inference.editing.edit_motion`, :func:`simdiff.inference.timeline.sample_timeline`) through the
:class:`~simdiff.serve.service.MotionService` queue: one request holds the model at a time, and a request whose
client goes away is dropped while it waits or at the next sampler step. A motion is named by the ``motion`` number
of the answer that sent it (:meth:`~simdiff.serve.service.MotionService.motion`), so no joints are uploaded.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from simdiff.errors import NonFiniteResult, SimdiffError
from simdiff.motion.skeleton import FPS, NUM_JOINTS
from simdiff.serve.params import (
    MAX_REPLAY_FRAMES,
    GenerateParams,
    ReplayParams,
    TimelineParams,
    parse_generate,
    parse_replay,
    parse_timeline_request,
)

if TYPE_CHECKING:
    from simdiff.diffusion.config import SamplingConfig
    from simdiff.serve.service import MotionService

Progress = Callable[[Iterable[Any]], Iterable[Any]]


def check_finite(values: Any) -> None:
    """Raise :class:`NonFiniteResult` (the API's 422) when ``values`` hold NaN or infinities."""
    if not np.all(np.isfinite(np.asarray(values))):
        raise NonFiniteResult("the sampler produced non-finite values with these settings; try other settings "
                              "(fewer steps, lower guidance) or another seed")


def pinned_keyframes(motion: Callable[[int, str], np.ndarray], params: GenerateParams) -> np.ndarray | None:
    """Keyframes (``params.frames``, 22, 3) metres for a generation with pins, NaN but for frame 0 = the first pose
    of motion ``pin_start`` and the last frame = the last pose of motion ``pin_end``; None without pins.

    Args:
        motion: ``(number, field) -> (T, 22, 3) joints`` of a motion shown (raises for an unknown number).
    Raises:
        SimdiffError: an unknown motion, or poses no motion of this length reaches or of two skeletons
            (:func:`~simdiff.inference.keyframes.check_keyframes`); one line naming the value.
    """
    from simdiff.inference.keyframes import check_keyframes

    if params.pin_start is None and params.pin_end is None:
        return None
    keys = np.full((params.frames, NUM_JOINTS, 3), np.nan)
    if params.pin_start is not None:
        keys[0] = motion(params.pin_start, "pin_start")[0]
    if params.pin_end is not None:
        keys[-1] = motion(params.pin_end, "pin_end")[-1]
    return check_keyframes(keys, f"the poses pinned on a {params.frames / FPS:g} s motion")


def sample_generation(generator: Any, params: GenerateParams, keys: np.ndarray | None, config: SamplingConfig,
                      env: tuple[float, float, float] | None, progress: Progress) -> np.ndarray:
    """The joints (T, 22, 3) float32 metres ``simdiff generate`` writes for ``params``: a plain sample, or with
    ``keys`` (:func:`pinned_keyframes`) a keyframed one, as ``generate --keyframes``.

    Raises:
        NonFiniteResult: the sample holds NaN or infinities.
    """
    from simdiff.inference.keyframes import sample_keyframed
    from simdiff.motion.rigid import joints_from_features

    if keys is None:
        out = generator.generate([params.text], params.frames, config, env=env, seed=params.seed, progress=progress)
        features = out.clips()[0].detach().cpu().numpy().astype(np.float32)
        check_finite(features)
        joints = joints_from_features(features, config.foot_lock)
    else:
        features, joints = sample_keyframed(generator, keys, config, text_embeddings=generator.encode_text([params.text]),
                                            env=env, seed=params.seed, progress=progress)
        check_finite(features)
    check_finite(joints)
    return joints


def pin_report(params: GenerateParams, keys: np.ndarray | None, joints: np.ndarray) -> dict[str, Any]:
    """``{pins: {start, end}, keyframe_error_cm}`` for a generation with pins (the largest distance of the
    generated joints from a pinned entry, cm); nothing without."""
    if keys is None:
        return {}
    from simdiff.inference.keyframes import keyframe_error

    return {"pins": {"start": params.pin_start, "end": params.pin_end},
            "keyframe_error_cm": round(100.0 * keyframe_error(np.asarray(joints), keys), 2)}


def replay(service: MotionService, params: ReplayParams, cancelled: Callable[[], bool] | None = None) -> dict[str, Any]:
    """``POST /api/edit``: motion ``params.source`` re-played under φ (:func:`~simdiff.inference.editing.edit_motion`,
    as ``simdiff edit``); ``meta`` gives how far the joints moved (``changed_m``, mean, metres) and the gravity read
    from the flights before and after (``gravity_read``, as ``edit.json``).

    Raises:
        SimdiffError: unknown source, a motion that is not a body in metres, under 0.5 s or over
            :data:`~simdiff.serve.params.MAX_REPLAY_FRAMES`, or a model without φ as numbers.
        QueueFull, ModelUnavailable, GenerationCancelled, NonFiniteResult: as
            :meth:`~simdiff.serve.service.MotionService.generate`.
    """
    from simdiff.inference.editing import check_motion, edit_motion
    from simdiff.product.edit import check_replay_model, gravity_readings
    from simdiff.product.pipeline import floor_contact

    joints = service.motion(params.source)
    if joints.shape[0] > MAX_REPLAY_FRAMES:
        raise SimdiffError(f"source {params.source} has {joints.shape[0]} frames; the viewer re-plays up to "
                           f"{MAX_REPLAY_FRAMES} ({MAX_REPLAY_FRAMES / FPS:g} s): use simdiff edit for longer ones")
    joints = check_motion(joints, f"source {params.source}")
    with service.queued(cancelled) as (position, queued), service.turn() as generator:
        check_replay_model(generator, service.model_dir)
        start = time.perf_counter()
        config = service.sampling(params)
        edited = edit_motion(generator, joints, config, (params.gravity, params.wind_x, params.wind_y),
                             seed=params.seed, text=params.text, progress=service.checked_steps)
        elapsed = time.perf_counter() - start
        number = service.next_id()
    check_finite(edited.joints)
    meta = {"source": "edit", "id": number, "params": params.as_dict(), "model": str(service.model_dir),
            "sampling": config.to_dict(), "elapsed_s": round(elapsed, 3), "changed_m": round(edited.changed_m, 4),
            "gravity_read": gravity_readings(joints, edited.joints), **floor_contact(edited.joints),
            "queue_position": position, "waited_s": round(start - queued, 3)}
    return service.answer(edited.joints, meta)


def timeline(service: MotionService, params: TimelineParams,
             cancelled: Callable[[], bool] | None = None) -> dict[str, Any]:
    """``POST /api/timeline``: one motion through the segments (:func:`~simdiff.inference.timeline.sample_timeline`,
    as ``generate --timeline``); ``meta.segments`` gives each one's text, frames ``[start, end)`` and φ.

    Raises:
        QueueFull, ModelUnavailable, GenerationCancelled, NonFiniteResult, SimdiffError: as
            :meth:`~simdiff.serve.service.MotionService.generate`.
    """
    from simdiff.inference.coverage import prompt_warnings
    from simdiff.inference.timeline import sample_timeline, spans
    from simdiff.product.pipeline import floor_contact

    with service.queued(cancelled) as (position, queued), service.turn() as generator:
        start = time.perf_counter()
        config = service.sampling(params)
        features, joints = sample_timeline(generator, params.segments, config, seed=params.seed,
                                           progress=service.checked_steps)
        elapsed = time.perf_counter() - start
        number = service.next_id()
        uses_env = bool(generator.is_simdiff)
        warnings = prompt_warnings(service.model_dir, [s.text for s in params.segments], generator)
    check_finite(features)
    check_finite(joints)
    segments = [{"text": s.text, "frames": list(span), "gravity": s.env.gravity, "wind": [s.env.wind_x, s.env.wind_y]}
                for s, span in zip(params.segments, spans(params.segments))]
    meta = {"source": "timeline", "id": number, "segments": segments, "seed": params.seed, "warnings": warnings,
            "model": str(service.model_dir), "env_used": uses_env, "sampling": config.to_dict(),
            "elapsed_s": round(elapsed, 3), **floor_contact(joints), "queue_position": position,
            "waited_s": round(start - queued, 3)}
    return service.answer(joints, meta)


def _generate(service: MotionService, body: Any, cancelled: Callable[[], bool]) -> dict[str, Any]:
    return service.generate(parse_generate(body), cancelled)


def _edit(service: MotionService, body: Any, cancelled: Callable[[], bool]) -> dict[str, Any]:
    return replay(service, parse_replay(body), cancelled)


def _timeline(service: MotionService, body: Any, cancelled: Callable[[], bool]) -> dict[str, Any]:
    return timeline(service, parse_timeline_request(body), cancelled)


POSTS: dict[str, Callable[[MotionService, Any, Callable[[], bool]], dict[str, Any]]] = {
    "/api/generate": _generate, "/api/edit": _edit, "/api/timeline": _timeline}
"""The JSON routes: path → ``(service, decoded body, cancelled) -> answer`` (``cancelled``: the client went away)."""
