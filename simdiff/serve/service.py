"""What the viewer's API does: lazy model loading, serialised generation, opening motion files.

The HTTP layer (:mod:`simdiff.serve.server`) only decodes requests and encodes answers; this
module holds the state (one model, one lock, the files named on the command line).
"""

from __future__ import annotations

import os
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from simdiff import __version__
from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.serve.params import GenerateParams, limits
from simdiff.serve.payload import motion_payload, skeleton_info

DEFAULT_PROMPT: str = "a person walks forward"
UPLOAD_SUFFIXES: tuple[str, ...] = (".npy", ".bvh", ".json", ".txt")
"""File types an upload may have (an ``.amc`` needs its ``.asf`` beside it: give it on the command line)."""

Progress = Callable[[Iterable[Any]], Iterable[Any]]


MAX_QUEUE: int = 4
"""Generation requests that may wait behind the running one before the API answers 429."""


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
        except Exception as exc:  # unreadable config.json: reported, the page shows it
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

    def generate(self, params: GenerateParams) -> dict[str, Any]:
        """``POST /api/generate``: one motion from the prompt and φ; requests run one at a time.

        At most ``max_queue`` requests wait behind the running one; the answer's ``meta`` gives the
        request's ``queue_position`` (requests ahead when it arrived) and ``waited_s``.

        Raises:
            QueueFull: ``max_queue`` requests are already waiting.
            ModelUnavailable: no loadable model.
            SimdiffError: the model rejected the request.
        """
        with self._admit:
            if self._pending > self.max_queue:
                raise QueueFull(self._pending, self.max_queue)
            position = self._pending  # requests ahead of this one
            self._pending += 1
        queued = time.perf_counter()
        try:
            return self._generate_admitted(params, position, queued)
        finally:
            with self._admit:
                self._pending -= 1

    def queue_status(self) -> dict[str, int]:
        """``{pending, limit}``: generation requests running or waiting, and how many may wait."""
        return {"pending": self._pending, "limit": self.max_queue}

    def _generate_admitted(self, params: GenerateParams, position: int, queued: float) -> dict[str, Any]:
        from simdiff.motion.features import features_to_joints

        with self._lock:
            generator = self._load_locked()
            uses_env = generator.is_simdiff
            start = time.perf_counter()
            waited = start - queued
            config = self.sampling(params)
            out = generator.generate([params.text], params.frames, config,
                                     env=(params.gravity, params.wind_x, params.wind_y) if uses_env else None,
                                     seed=params.seed, progress=self._progress)
            elapsed = time.perf_counter() - start
            self._count += 1
            number = self._count
        features = out.clips()[0].detach().cpu().numpy().astype(np.float32)
        joints = features_to_joints(features)
        from simdiff.product.pipeline import floor_contact

        meta = {"source": "generate", "id": number, "params": params.as_dict(), "model": str(self.model_dir),
                "kind": self._kind(generator.config), "env_used": uses_env, "sampling": config.to_dict(),
                "elapsed_s": round(elapsed, 3), **floor_contact(joints),
                "queue_position": position, "waited_s": round(waited, 3)}
        if params.simulate:
            from simdiff.product.pipeline import normalizer_of
            from simdiff.product.simulate import simulate_finish
            from simdiff.serve.payload import DECIMALS
            from simdiff.sim.env import Environment

            env = Environment(params.gravity, params.wind_x, params.wind_y) if uses_env else None
            sim = simulate_finish(np.asarray(joints), env, normalizer=normalizer_of(generator))
            meta["simulated"] = sim.tracking
            meta["generated_joints"] = np.round(np.asarray(joints, dtype=np.float64), DECIMALS).tolist()
            meta["elapsed_s"] = round(time.perf_counter() - start, 3)
            return motion_payload(sim.joints, meta)
        return motion_payload(joints, meta)

    def open_listed(self, index: int) -> dict[str, Any]:
        """``GET /api/files/<index>``: a motion named on the command line."""
        if not 0 <= index < len(self.files):
            raise SimdiffError(f"no listed file {index} (there are {len(self.files)})")
        item = self.files[index]
        return motion_payload(item.joints, {"source": "file", "name": item.name, "path": str(item.path)})

    def open_upload(self, name: str, data: bytes) -> dict[str, Any]:
        """``POST /api/open``: read an uploaded motion file (written to a temporary folder first).

        Args:
            name: the file's name on the user's machine (its extension picks the reader).
            data: the file's bytes.
        Raises:
            SimdiffError: unsupported type or unreadable file; the message names ``name``, not the temp path.
        """
        from simdiff.motion.io import load_joints

        base = Path(name.replace("\\", "/")).name.strip()
        suffix = Path(base).suffix.lower()
        if not base or base in (".", ".."):
            raise SimdiffError(f"upload needs a file name, got {name!r}")
        if suffix not in UPLOAD_SUFFIXES:
            raise SimdiffError(f"{base}: unsupported file type {suffix or '(none)'!r}; open "
                               ".npy joints (T, 22, 3) or features (T, 263), .bvh, or DeepMimic .txt/.json")
        if not data:
            raise SimdiffError(f"{base}: empty file")
        with tempfile.TemporaryDirectory(prefix="simdiff-serve-") as tmp:
            path = Path(tmp) / base
            path.write_bytes(data)
            try:
                joints = load_joints(path)
            except SimdiffError as exc:
                raise SimdiffError(str(exc).replace(str(path), base)) from None
            except Exception as exc:  # a reader tripping over garbage is still bad user input
                detail = str(exc).replace(str(path), base).splitlines()
                raise SimdiffError(f"{base}: cannot read: {type(exc).__name__}: {detail[0] if detail else ''}") from None
        return motion_payload(joints, {"source": "upload", "name": base, "bytes": len(data)})
