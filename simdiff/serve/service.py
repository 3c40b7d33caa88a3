"""What the viewer's API does: lazy model loading, serialised generation, opening motion files.

The HTTP layer (:mod:`simdiff.serve.server`) only decodes requests and encodes answers; this
module holds the state (one model, one lock, the files named on the command line).
"""

from __future__ import annotations

import math
import os
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simdiff import __version__
from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS
from simdiff.serve.edits import (
    check_finite,
    pin_report,
    pinned_keyframes,
    sample_generation,
)
from simdiff.serve.params import GenerateParams, limits
from simdiff.serve.payload import motion_payload, skeleton_info
from simdiff.serve.wire import BodyCache

DEFAULT_PROMPT: str = "a person walks forward"
UPLOAD_SUFFIXES: tuple[str, ...] = (".npy", ".bvh", ".json", ".txt")
"""File types an upload may have (an ``.amc`` needs its ``.asf`` beside it: give it on the command line)."""

Progress = Callable[[Iterable[Any]], Iterable[Any]]


MAX_QUEUE: int = 4
"""Generation requests that may wait behind the running one before the API answers 429."""
CANCEL_POLL_S: float = 0.1
"""How often a queued generation request checks whether its client went away."""
MAX_OPEN_FRAMES: int = 12_000
"""Longest motion an upload or listed file may have (10 minutes at 20 fps): bounds the answer (about 6 MB of
JSON) and the memory it takes to build it. Longer files are refused with :class:`MotionTooLong` (413)."""
UPLOADS_AT_ONCE: int = 2
"""Uploads read (parsed) at the same time; more are refused with :class:`UploadsBusy` (503)."""
MAX_NAME_BYTES: int = 255
"""Longest upload file name in UTF-8 bytes (a file system's limit)."""
MAX_BODIES: int = 4
"""Motions whose skinned body (``GET /api/body/<n>.glb``) and joints (a ``source`` or pin) the server keeps
(see :class:`~simdiff.serve.wire.BodyCache`)."""


class ModelUnavailable(SimdiffError):
    """The model folder is missing or cannot be loaded (the API answers 503)."""


class QueueFull(SimdiffError):
    """Too many generation requests are waiting (the API answers 429 with the queue's length).

    Attributes:
        waiting: requests ahead (running and queued) when this one was refused.
        limit: the queue's size.
    """

    def __init__(self, waiting: int, limit: int) -> None:
        super().__init__(f"the server is busy: {waiting} generation request(s) ahead, the queue holds {limit}; "
                         "try again in a moment")
        self.waiting = waiting
        self.limit = limit


class GenerationCancelled(SimdiffError):
    """The client went away: its queued or running generation was dropped (nothing is answered)."""


class UploadsBusy(SimdiffError):
    """:data:`UPLOADS_AT_ONCE` uploads are being read already (the API answers 503)."""


class MotionTooLong(SimdiffError):
    """An opened motion has more than :data:`MAX_OPEN_FRAMES` frames (the API answers 413)."""


@dataclass(frozen=True)
class ListedMotion:
    """A motion file named on the command line, read once at start-up.

    Attributes:
        name: file name shown on the page.
        path: where it was read from.
        joints: (T, 22, 3) float32 metres, Y-up, 20 fps.
    """

    name: str
    path: Path
    joints: np.ndarray


def read_listed(paths: Sequence[str | os.PathLike[str]], progress: Progress | None = None) -> list[ListedMotion]:
    """Read motion files with :func:`simdiff.motion.io.load_joints`.

    Raises:
        SimdiffError: one line naming the first unreadable file.
    """
    from simdiff.motion.io import load_joints

    items = [Path(p) for p in paths]
    return [ListedMotion(p.name, p, load_joints(p)) for p in (progress(items) if progress else items)]


class MotionService:
    """The viewer's back end: generate with a lazily loaded model, open files.

    Args:
        model: model folder (default ``$SIMDIFF_MODEL`` or the shipped one); loaded on first use.
        device: torch device for generation.
        files: motions named on the command line (see :func:`read_listed`).
        text_encoder: replaces the model's own text encoder (tests use a hash encoder; the model
            is then loaded without MiniLM).
        progress: wraps the sampler's step iterator (e.g. a tqdm bar on the server's console).
        steps: denoising steps when a request names none (None: the model's).
        max_queue: generation requests that may wait behind the running one (more: :class:`QueueFull`).
    """

    def __init__(self, model: str | os.PathLike[str] | None = None, *, device: str = "cpu",
                 files: Sequence[ListedMotion] = (), text_encoder: object | None = None,
                 progress: Progress | None = None, steps: int | None = None, max_queue: int = MAX_QUEUE) -> None:
        from simdiff.inference.default import default_model_dir

        self.model_dir = default_model_dir(model)
        self.device = device
        self.files = list(files)
        self._text_encoder = text_encoder
        self._progress = progress
        self.steps = steps
        self._generator: Any = None
        self._lock = threading.Lock()
        self._count = 0
        if max_queue < 0:
            raise SimdiffError(f"max_queue must be ≥ 0, got {max_queue}")
        self.max_queue = max_queue
        self._admit = threading.Lock()
        self._pending = 0  # running + waiting generation requests
        self._request = threading.local()  # the handler thread's ``cancelled`` check (see generate)
        self._uploads = threading.BoundedSemaphore(UPLOADS_AT_ONCE)
        self.bodies = BodyCache(MAX_BODIES)

    # -- model -------------------------------------------------------------------------------

    def model_status(self) -> dict[str, Any]:
        """``{path, found, loaded, kind, env, error}`` without loading the weights.

        ``kind`` is ``simdiff`` (continuous φ), ``backbone`` (no φ: the sliders do nothing) or None.
        """
        found = all((self.model_dir / n).is_file() for n in ("config.json", "model.safetensors"))
        status: dict[str, Any] = {"path": str(self.model_dir), "found": found, "loaded": self._generator is not None,
                                  "kind": None, "env": False, "error": None}
        if not found:
            status["error"] = f"no model in {self.model_dir} (pass --model DIR or set SIMDIFF_MODEL)"
            return status
        try:
            from simdiff.model.checkpoint import read_config

            config = self._generator.config if self._generator is not None else read_config(self.model_dir)
            status["kind"] = self._kind(config)
        except Exception as exc:  # noqa: BLE001 (unreadable config.json: reported, the page shows it)
            status["error"] = f"{self.model_dir}: cannot read config.json: {exc}".splitlines()[0]
            return status
        status["env"] = status["kind"] == "simdiff"
        if status["kind"] == "categorical":
            status["error"] = f"{self.model_dir}: categorical SimDiff models are not supported by the viewer"
        return status

    @staticmethod
    def _kind(config: Any) -> str:
        if config.sim is None:
            return "backbone"
        return "simdiff" if config.sim.mode == "continuous" else "categorical"

    def sampling(self, params: GenerateParams | None = None, strict: bool = True) -> SamplingConfig:
        """The model's :class:`SamplingConfig` (``sampling.json``) with ``params``' settings over it, as
        ``simdiff generate`` does (and the server's ``steps`` when the request names none). A bad file is the
        model's error when ``strict``, else ignored (the page's defaults still load); a bad request value is the
        request's error."""
        from simdiff.inference.default import sampling_config

        try:
            base = sampling_config(self.model_dir)
        except SimdiffError as exc:
            if strict:
                raise ModelUnavailable(str(exc)) from None
            base = SamplingConfig()
        given = {} if params is None else params.sampling()
        if self.steps is not None:
            given.setdefault("steps", self.steps)
        return base.updated(**given)

    def _load_locked(self) -> Any:
        """The generator, loaded on first call (caller holds the lock)."""
        if self._generator is None:
            from simdiff.inference.default import load_default

            try:
                generator = load_default(self.model_dir, self.device, load_text=self._text_encoder is None)
            except SimdiffError as exc:
                raise ModelUnavailable(str(exc)) from None
            if self._kind(generator.config) == "categorical":
                raise ModelUnavailable(f"{self.model_dir}: categorical SimDiff models are not supported by the viewer")
            if self._text_encoder is not None:
                generator.text_encoder = self._text_encoder
            self._generator = generator
        return self._generator

    # -- API ---------------------------------------------------------------------------------

    def info(self) -> dict[str, Any]:
        """``GET /api/info``: version, model status, listed files, slider ranges, defaults, skeleton."""
        return {
            "version": __version__,
            "model": self.model_status(),
            "files": [{"index": i, "name": f.name, "frames": int(f.joints.shape[0])} for i, f in enumerate(self.files)],
            "limits": limits(),
            "queue": self.queue_status(),
            "defaults": {**GenerateParams(text=DEFAULT_PROMPT).as_dict(), **self.sampling(strict=False).to_dict()},
            "skeleton": skeleton_info(),
        }

    def generate(self, params: GenerateParams, cancelled: Callable[[], bool] | None = None) -> dict[str, Any]:
        """``POST /api/generate``: one motion from the prompt and φ; requests run one at a time.

        At most ``max_queue`` requests wait behind the running one; the answer's ``meta`` gives the
        request's ``queue_position`` (requests ahead when it arrived) and ``waited_s``. Pinned poses
        (``pin_start``, ``pin_end``) make it a keyframed sample (:func:`~simdiff.serve.edits.pinned_keyframes`).

        Args:
            params: the validated request.
            cancelled: polled while the request waits (every :data:`CANCEL_POLL_S`) and at every sampler
                step; True drops the request (the server passes "the client closed its connection").
        Raises:
            QueueFull: ``max_queue`` requests are already waiting.
            ModelUnavailable: no loadable model.
            GenerationCancelled: ``cancelled()`` turned True.
            NonFiniteResult: the sampler produced NaN or infinite values.
            SimdiffError: the model rejected the request, or a pin names no motion kept or a pose out of reach.
        """
        keys = pinned_keyframes(self.motion, params)  # refused before it queues
        with self.queued(cancelled) as (position, queued):
            return self._generate_admitted(params, keys, position, queued)

    @contextmanager
    def queued(self, cancelled: Callable[[], bool] | None) -> Iterator[tuple[int, float]]:
        """A place in the generation queue for one request's whole run: (requests ahead, ``perf_counter`` when
        it queued); ``cancelled`` is what :meth:`turn` and :meth:`checked_steps` poll meanwhile.

        Raises:
            QueueFull: ``max_queue`` requests are already waiting.
        """
        with self._admit:
            if self._pending > self.max_queue:
                raise QueueFull(self._pending, self.max_queue)
            position = self._pending  # requests ahead of this one
            self._pending += 1
        self._request.cancelled = cancelled
        try:
            yield position, time.perf_counter()
        finally:
            self._request.cancelled = None
            with self._admit:
                self._pending -= 1

    @contextmanager
    def turn(self) -> Iterator[Any]:
        """The model, held by this request alone (waiting for the running one, cancellable; loaded on first use).

        Raises:
            GenerationCancelled: the client went away while waiting.
            ModelUnavailable: no loadable model.
        """
        self._wait_turn()
        try:
            yield self._load_locked()
        finally:
            self._lock.release()

    def next_id(self) -> int:
        """The next motion's ``meta.id`` (the model's motions so far; call during :meth:`turn`)."""
        self._count += 1
        return self._count

    def queue_status(self) -> dict[str, int]:
        """``{pending, limit}``: generation requests running or waiting, and how many may wait."""
        return {"pending": self._pending, "limit": self.max_queue}

    def _check_cancelled(self, when: str) -> None:
        cancelled = getattr(self._request, "cancelled", None)
        if cancelled is not None and cancelled():
            raise GenerationCancelled(f"the client went away {when}: generation dropped")

    def _wait_turn(self) -> None:
        """Take the model lock, giving up when the request is cancelled while it waits."""
        while not self._lock.acquire(timeout=CANCEL_POLL_S):
            self._check_cancelled("while queued")
        try:
            self._check_cancelled("while queued")
        except GenerationCancelled:
            self._lock.release()
            raise

    def checked_steps(self, steps: Iterable[Any]) -> Iterator[Any]:
        """The sampler's timesteps through ``progress``, checking for cancellation before each step."""
        for step in self._progress(steps) if self._progress is not None else steps:
            self._check_cancelled("during sampling")
            yield step

    def _generate_admitted(self, params: GenerateParams, keys: np.ndarray | None, position: int,
                           queued: float) -> dict[str, Any]:
        from simdiff.inference.coverage import prompt_warnings
        from simdiff.product.pipeline import floor_contact

        with self.turn() as generator:
            uses_env = generator.is_simdiff
            start = time.perf_counter()
            config = self.sampling(params)
            env = (params.gravity, params.wind_x, params.wind_y) if uses_env else None
            joints = sample_generation(generator, params, keys, config, env, self.checked_steps)
            elapsed, number = time.perf_counter() - start, self.next_id()
            warnings = prompt_warnings(self.model_dir, [params.text], generator)
        meta = {"source": "generate", "id": number, "params": params.as_dict(), "model": str(self.model_dir),
                "warnings": warnings,
                "kind": self._kind(generator.config), "env_used": uses_env, "sampling": config.to_dict(),
                "elapsed_s": round(elapsed, 3), **floor_contact(joints),
                "queue_position": position, "waited_s": round(start - queued, 3), **pin_report(params, keys, joints)}
        if params.simulate:
            from simdiff.product.pipeline import normalizer_of
            from simdiff.product.simulate import simulate_finish
            from simdiff.serve.payload import DECIMALS
            from simdiff.sim.env import Environment

            self._check_cancelled("before the simulation")
            env = Environment(params.gravity, params.wind_x, params.wind_y) if uses_env else None
            sim = simulate_finish(np.asarray(joints), env, normalizer=normalizer_of(generator))
            check_finite(sim.joints)
            meta["simulated"] = sim.tracking
            meta["generated_joints"] = np.round(np.asarray(joints, dtype=np.float64), DECIMALS).tolist()
            meta["elapsed_s"] = round(time.perf_counter() - start, 3)
            return self.answer(sim.joints, meta)
        return self.answer(joints, meta)

    def answer(self, joints: np.ndarray, meta: dict[str, Any]) -> dict[str, Any]:
        """:func:`motion_payload` plus ``motion`` (its number, for requests that name it as a source) and ``body``:
        where the page gets the motion's skinned body (:meth:`body`)."""
        payload = motion_payload(joints, meta)
        payload["motion"] = self.bodies.add(np.asarray(payload["joints"]))
        payload["body"] = f"/api/body/{payload['motion']}.glb"
        return payload

    def motion(self, number: int, key: str = "source") -> np.ndarray:
        """(T, 22, 3) joints of the answer numbered ``number`` as sent (a request's ``key`` names it).

        Raises:
            SimdiffError: it is not among the last :data:`MAX_BODIES` motions (each use keeps it there).
        """
        joints = self.bodies.joints(number)
        if joints is None:
            raise SimdiffError(f"{key} {number}: no such motion here (the server keeps the last {MAX_BODIES} "
                               "motions shown); open or generate it again")
        return joints.copy()  # the kept joints stay as sent

    def body(self, number: int) -> bytes | None:
        """``GET /api/body/<number>.glb``: the skinned body of an answer, built from its joints as sent; None when
        it is not among the last :data:`MAX_BODIES` answers."""
        return self.bodies.glb(number)

    def open_listed(self, index: int) -> dict[str, Any]:
        """``GET /api/files/<index>``: a motion named on the command line.

        Raises:
            SimdiffError: no such index.
            MotionTooLong: the file has more than :data:`MAX_OPEN_FRAMES` frames.
        """
        if not 0 <= index < len(self.files):
            raise SimdiffError(f"no listed file {index} (there are {len(self.files)})")
        item = self.files[index]
        _check_frames(item.name, int(item.joints.shape[0]))
        return self.answer(item.joints, {"source": "file", "name": item.name, "path": str(item.path)})

    @staticmethod
    def upload_name(name: str) -> str:
        """The name an upload is read under (its base name), checked before its bytes are read.

        Raises:
            SimdiffError: no name, control characters (NUL, newline), over :data:`MAX_NAME_BYTES`, or an
                unsupported extension.
        """
        if any(ord(c) < 32 or ord(c) == 127 for c in name):
            raise SimdiffError("upload name must not contain control characters (NUL, newline, ...)")
        base = Path(name.replace("\\", "/")).name.strip()
        if not base or base in (".", ".."):
            raise SimdiffError(f"upload needs a file name, got {name[:40]!r}")
        try:
            size = len(base.encode("utf-8"))
        except UnicodeEncodeError:
            raise SimdiffError("upload name is not valid text") from None
        if size > MAX_NAME_BYTES:
            raise SimdiffError(f"upload name {base[:24]!r}... is {size} bytes long; the limit is {MAX_NAME_BYTES}")
        suffix = Path(base).suffix.lower()
        if suffix not in UPLOAD_SUFFIXES:
            raise SimdiffError(f"{base}: unsupported file type {suffix or '(none)'!r}; open "
                               ".npy joints (T, 22, 3) or features (T, 263), .bvh, or DeepMimic .txt/.json")
        return base

    def open_upload(self, name: str, data: bytes | bytearray | memoryview) -> dict[str, Any]:
        """``POST /api/open``: read an uploaded motion file (written to a temporary folder, then
        :meth:`open_upload_file`).

        Args:
            name: the file's name on the user's machine (its extension picks the reader).
            data: the file's bytes.
        Raises:
            SimdiffError, MotionTooLong, UploadsBusy: see :meth:`upload_name` and :meth:`open_upload_file`.
        """
        base = self.upload_name(name)
        with tempfile.TemporaryDirectory(prefix="simdiff-serve-") as tmp:
            path = Path(tmp) / base
            path.write_bytes(data)
            return self.open_upload_file(base, path)

    def open_upload_file(self, name: str, path: Path) -> dict[str, Any]:
        """Read an upload already written to ``path`` (named ``name``, from :meth:`upload_name`, in a temporary
        folder): at most :data:`UPLOADS_AT_ONCE` at a time, since a reader can take several times the file's size.

        Raises:
            SimdiffError: empty or unreadable file; the message names ``name``, never ``path``.
            MotionTooLong: more than :data:`MAX_OPEN_FRAMES` frames (from a ``.npy`` or ``.bvh`` header before
                the file is parsed, else after).
            UploadsBusy: :data:`UPLOADS_AT_ONCE` uploads are being read already.
        """
        from simdiff.motion.io import load_joints

        size = path.stat().st_size
        if not size:
            raise SimdiffError(f"{name}: empty file")

        def clean(text: str) -> str:
            return text.replace(str(path), name).replace(str(path.parent), "")

        if not self._uploads.acquire(blocking=False):
            raise UploadsBusy(f"the server is busy reading {UPLOADS_AT_ONCE} other uploads; try again in a moment")
        try:
            _check_frames(name, _frames_in_header(path))
            joints = load_joints(path)
        except MotionTooLong:
            raise
        except SimdiffError as exc:
            raise SimdiffError(clean(str(exc))) from None
        except Exception as exc:  # noqa: BLE001 (a reader tripping over garbage is bad input)
            detail = clean(str(exc)).splitlines()
            raise SimdiffError(f"{name}: cannot read: {type(exc).__name__}: {detail[0] if detail else ''}") from None
        finally:
            self._uploads.release()
        _check_frames(name, int(joints.shape[0]))
        return self.answer(joints, {"source": "upload", "name": name, "bytes": size})


def _check_frames(name: str, frames: int | None) -> None:
    if frames is not None and frames > MAX_OPEN_FRAMES:
        raise MotionTooLong(f"{name}: {frames} frames ({frames / FPS:.0f} s at {FPS} fps) is over the viewer's "
                            f"limit of {MAX_OPEN_FRAMES} frames ({MAX_OPEN_FRAMES / FPS:.0f} s)")


def _frames_in_header(path: Path) -> int | None:
    """Frames at 20 fps that a ``.npy`` or ``.bvh`` file declares in its header (None: not known before parsing)."""
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            with path.open("rb") as handle:
                version = np.lib.format.read_magic(handle)
                read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                shape = read(handle)[0]
            return int(shape[0]) if len(shape) else None
        if suffix == ".bvh":
            frames = None
            with path.open("r", encoding="utf-8", errors="replace") as handle:
                for number, line in enumerate(handle):
                    words = line.split()
                    if words[:1] == ["Frames:"] and len(words) == 2:
                        frames = int(words[1])
                    elif words[:2] == ["Frame", "Time:"] and len(words) == 3 and frames is not None:
                        return math.ceil(frames * float(words[2]) * FPS)
                    elif number > 100_000:
                        return None
    except (ValueError, OSError, OverflowError):
        return None  # the reader names what is wrong
    return None
