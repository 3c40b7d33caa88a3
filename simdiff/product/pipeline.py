"""The generation pipeline behind ``simdiff generate``: prompt → features → joints → files, timed.

Sample ``k`` under every environment starts from the same noise (seed ``seed + k``), so a
``--compare`` video shows the effect of φ alone, and ``--seed S --num-samples 1`` reproduces
sample ``k`` of ``--seed S-k``.
"""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Iterable, Iterator

import numpy as np

from simdiff import __version__
from simdiff.errors import SimdiffError
from simdiff.fsio import output_set
from simdiff.motion.skeleton import FPS
from simdiff.product.outputs import env_label, render_video, write_metadata, write_motion
from simdiff.product.request import GenerationRequest
from simdiff.product.simulate import SimulatedMotion, load_simulator, simulate_finish, write_simulated
from simdiff.sim.env import Environment

if TYPE_CHECKING:
    from simdiff.inference.coverage import PromptCoverage
    from simdiff.product.finisher import Finisher

FEATURES_NOTE = ("(T, 263) float32 un-normalised HumanML3D features, one row per joint frame as the model "
                 "samples them (MDM convention); joints = simdiff.motion.rigid.joints_from_features(features, foot_lock)")


@dataclass
class Timer:
    """Wall-clock and process-CPU seconds per named stage (stages may repeat; times add up)."""

    wall: dict[str, float] = field(default_factory=dict)
    cpu: dict[str, float] = field(default_factory=dict)

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        w, c = time.perf_counter(), time.process_time()
        try:
            yield
        finally:
            self.wall[name] = self.wall.get(name, 0.0) + time.perf_counter() - w
            self.cpu[name] = self.cpu.get(name, 0.0) + time.process_time() - c

    def rounded(self, which: dict[str, float]) -> dict[str, float]:
        """Stage → seconds (3 decimals) plus ``total``."""
        out = {k: round(v, 3) for k, v in which.items()}
        out["total"] = round(sum(which.values()), 3)
        return out


@dataclass
class Sample:
    """One generated motion.

    Attributes:
        column: index of its environment in ``request.envs``.
        index: sample number k (seed = request.seed + k).
        env: φ it was generated under; None for a backbone-only model.
        features: (T, 263) float32 un-normalised features.
        joints: (T, 22, 3) float32 positions in metres, Y-up.
    """

    column: int
    index: int
    seed: int
    env: Environment | None
    features: np.ndarray
    joints: np.ndarray
    simulated: "SimulatedMotion | None" = None


def _progress(quiet: bool):
    """A ``progress(iterable, total, desc)`` wrapper printing a tqdm bar on stderr (nothing when quiet)."""
    from tqdm.auto import tqdm

    def wrap(iterable: Iterable, total: int, desc: str) -> Iterable:
        return tqdm(iterable, total=total, desc=desc, unit="frame", leave=False, disable=quiet, file=sys.stderr,
                    dynamic_ncols=True)

    return wrap


def sample_motions(generator, request: GenerationRequest, timer: Timer, quiet: bool = False) -> list[Sample]:
    """Encode the prompt once, sample every (environment, k) pair, and decode joints.

    Args:
        generator: a :class:`~simdiff.inference.generator.MotionGenerator` with a text encoder.
        request: the validated request; its environments are ignored for a backbone-only model.
    """
    from tqdm.auto import tqdm

    from simdiff.motion.rigid import joints_from_features

    simdiff_model = bool(generator.is_simdiff)
    envs: list[Environment | None] = list(request.envs) if simdiff_model else [None]
    with timer.stage("encode_text"):
        text = generator.encode_text([request.text])
    runs = [(c, k) for c in range(len(envs)) for k in range(request.num_samples)]
    windows = len(request.timeline) if request.timeline is not None else 1
    bar = tqdm(total=request.sampling.steps * len(runs) * windows, desc=f"{request.sampling.sampler} sampling", unit="step", leave=False,
               disable=quiet, file=sys.stderr, dynamic_ncols=True)

    def progress(steps: Iterable) -> Iterator:
        for t in steps:
            yield t
            bar.update(1)

    features: list[np.ndarray] = []
    written: list[np.ndarray | None] = []
    try:
        with timer.stage("sample"):
            for c, k in runs:
                env = None if envs[c] is None else envs[c].as_tuple()
                if request.timeline is not None:
                    from simdiff.inference.timeline import sample_timeline

                    f, j = sample_timeline(generator, request.timeline, request.sampling, seed=request.seed + k,
                                           progress=progress)
                    features.append(f)
                    written.append(j)
                    continue
                if request.keyframes is not None:
                    from simdiff.inference.keyframes import sample_keyframed

                    f, j = sample_keyframed(generator, request.keyframes, request.sampling, text_embeddings=text,
                                            env=env, seed=request.seed + k, progress=progress)
                    features.append(f)
                    written.append(j)
                    continue
                out = generator.generate([request.text], request.frames, request.sampling, env=env,
                                         seed=request.seed + k, text_embeddings=text, progress=progress)
                features.append(out.clips()[0].detach().cpu().numpy().astype(np.float32))
                written.append(None)
    finally:
        bar.close()
    samples = []
    with timer.stage("decode"):
        for (c, k), f, j in zip(runs, features, written):
            joints = joints_from_features(f, request.sampling.foot_lock) if j is None else j
            samples.append(Sample(c, k, request.seed + k, envs[c], f, joints))
    return samples


def describe_env(env: Environment | None) -> str:
    """``g -3.7 m/s², wind (2, 0) N`` (or ``no environment`` for a backbone-only model)."""
    if env is None:
        return "no environment (backbone-only model)"
    return f"g {env.gravity:g} m/s², wind ({env.wind_x:g}, {env.wind_y:g}) N"


def stem_name(request: GenerationRequest, sample: Sample) -> str:
    """File stem of a sample: ``sample0``, or ``gravity-3.7_sample0`` under ``--compare``."""
    if request.compare is None or sample.env is None:
        return f"sample{sample.index}"
    value = getattr(sample.env, request.compare)
    return f"{request.compare}{env_label(value)}_sample{sample.index}"


def write_outputs(samples: list[Sample], request: GenerationRequest, out_dir: Path, timer: Timer,
                  quiet: bool = False) -> tuple[list[dict[str, Path]], list[Path]]:
    """Write every sample's files and the videos; returns (kind → path per sample, video paths).

    Without ``--compare`` each sample gets its own video ``sampleK.gif``; with it, one video per
    k shows the environments side by side (``compare_sampleK.gif``).
    """
    files: list[dict[str, Path]] = []
    for s in samples:
        stem = out_dir / stem_name(request, s)
        written: dict[str, Path] = {}
        with timer.stage("write_npy"):
            written.update(write_motion(stem, s.joints, s.features, [f for f in request.formats if f == "npy"]))
        with timer.stage("write_bvh"):
            written.update(write_motion(stem, s.joints, s.features, [f for f in request.formats if f == "bvh"]))
        with timer.stage("write_glb"):
            written.update(write_motion(stem, s.joints, s.features, [f for f in request.formats if f == "glb"]))
        if s.simulated is not None:
            with timer.stage("write_simulated"):
                written.update(write_simulated(stem, s.simulated, list(request.formats)))
        files.append(written)
    videos: list[Path] = []
    progress = _progress(quiet)
    compare = request.compare is not None and len({s.column for s in samples}) > 1
    for kind in request.video_formats:
        with timer.stage(f"render_{kind}"):
            if compare:
                for k in range(request.num_samples):
                    group = [s for s in samples if s.index == k]
                    path = out_dir / f"compare_sample{k}.{kind}"
                    captions = [f"{request.text} · {describe_env(s.env)}" for s in group]
                    videos.append(render_video([s.joints for s in group], captions, path, FPS, progress))
                continue
            for s, written in zip(samples, files):
                path = out_dir / f"{stem_name(request, s)}.{kind}"
                written[kind] = render_video([s.joints], [f"{request.text} · {describe_env(s.env)}"], path, FPS,
                                             progress)
                videos.append(path)
    return files, videos


def _torch_threads() -> int:
    import torch

    return int(torch.get_num_threads())


def _env_dict(env: Environment) -> dict:
    return {"gravity": env.gravity, "wind": [env.wind_x, env.wind_y]}


def model_provenance(model_dir: Path) -> dict:
    """``trained_on`` and ``weights_licence`` from the model's ``provenance.json`` ("unknown" without one), and the
    recipe of ``extrapolation.json`` when its backbone was extrapolated (``simdiff train extrapolate``)."""
    from simdiff.model.extrapolate import read_recipe
    from simdiff.model.provenance import UNKNOWN, read_provenance

    prov = read_provenance(model_dir)
    recipe = read_recipe(model_dir)
    extra = {} if recipe is None else {"extrapolation": recipe}
    if prov is None:
        return {"trained_on": UNKNOWN, "weights_licence": UNKNOWN, **extra}
    return {"trained_on": [p.to_dict() for p in prov.trained_on], "weights_licence": prov.weights_licence, **extra}


def prompt_coverage(generator, request: GenerationRequest, model_dir: Path) -> list[PromptCoverage] | None:
    """The prompt (each timeline segment's text) against the model's training captions
    (:mod:`simdiff.inference.coverage`); None when the model folder has no caption table."""
    from simdiff.inference.coverage import check_prompts

    texts = [seg.text for seg in request.timeline] if request.timeline is not None else [request.text]
    return check_prompts(model_dir, texts, generator.encode_text, generator.config.text_encoder)


def _coverage_record(coverage: list[PromptCoverage] | None) -> dict | None:
    """``generation.json``'s ``prompt_coverage``: the threshold and each prompt's best match (None: not checked)."""
    if coverage is None:
        return None
    from simdiff.inference.coverage import COVERAGE_NAME, FAR_BELOW

    return {"table": COVERAGE_NAME, "far_below": FAR_BELOW, "prompts": [c.to_dict() for c in coverage]}


def metadata(request: GenerationRequest, generator, model_dir: Path, samples: list[Sample],
             files: list[dict[str, Path]], videos: list[Path], timer: Timer,
             coverage: list[PromptCoverage] | None = None) -> dict:
    """The ``generation.json`` record of one run (file names relative to the output folder); ``coverage``: the
    prompts checked against the training captions (:func:`prompt_coverage`), None when not checked."""
    from simdiff.motion.foot_lock import CLEANUP_VERSION

    cfg = generator.config
    simdiff_model = bool(generator.is_simdiff)
    records = [{"index": s.index, "seed": s.seed, "environment": None if s.env is None else _env_dict(s.env),
                "frames": int(s.joints.shape[0]), "files": {kind: p.name for kind, p in written.items()},
                **floor_contact(s.joints),
                **({"simulated": _simulated_summary(s.simulated)} if s.simulated is not None else {})}
               for s, written in zip(samples, files)]
    return {
        "simdiff_version": __version__,
        "prompt": request.text,
        "frames": request.frames,
        "seconds": request.seconds,
        "fps": FPS,
        "model": {
            "path": str(Path(model_dir).resolve()),
            "kind": f"simdiff ({cfg.sim.mode} environment)" if simdiff_model else "backbone only (environment ignored)",
            "latent_dim": cfg.backbone.latent_dim,
            "num_layers": cfg.backbone.num_layers,
            "text_encoder": cfg.text_encoder,
            **model_provenance(model_dir),
        },
        "environment": (_env_dict(request.envs[0])
                        if simdiff_model and request.compare is None and request.timeline is None else None),
        "compare": ({"component": request.compare,
                     "values": [getattr(e, request.compare) for e in request.envs]}
                    if simdiff_model and request.compare else None),
        "seed": request.seed,
        "num_samples": request.num_samples,
        **request.sampling.to_dict(),
        "alpha": request.sampling.alpha if simdiff_model else None,
        "env_guidance": request.sampling.env_guidance if simdiff_model else None,
        "edit_t": request.sampling.edit_t if simdiff_model else None,
        "foot_cleanup": CLEANUP_VERSION if request.sampling.foot_lock else None,
        "keyframes": _keyframes_record(request, samples),
        "timeline": _timeline_record(request),
        "prompt_coverage": _coverage_record(coverage),
        "features_layout": FEATURES_NOTE,
        "joints_layout": "(T, 22, 3) float32 metres, Y-up, 20 fps, HumanML3D joint order; forward kinematics of "
                         "rotations on one fixed skeleton per motion (bone lengths constant)",
        "samples": records,
        "videos": [p.name for p in videos],
        "threads": _torch_threads(),
        "timings_s": timer.rounded(timer.wall),
        "cpu_s": timer.rounded(timer.cpu),
    }


def _keyframes_record(request: GenerationRequest, samples: list[Sample]) -> dict | None:
    """The keyframe file, its finite entries and how far each sample's written joints are from them (m)."""
    keys = request.keyframes
    if keys is None:
        return None
    from simdiff.inference.keyframes import keyframe_error

    given = np.isfinite(keys)
    worst = [keyframe_error(s.joints, keys) for s in samples]
    return {"file": request.keyframes_file, "entries": int(given.all(-1).sum() + (given[:, 0].sum(-1) == 2).sum()),
            "max_error_m": [round(w, 4) for w in worst]}


def _timeline_record(request: GenerationRequest) -> list[dict] | None:
    """Each timeline segment: its text, frames [start, end) and environment."""
    if request.timeline is None:
        return None
    from simdiff.inference.timeline import spans

    return [{"text": seg.text, "frames": list(span), "environment": _env_dict(seg.env)}
            for seg, span in zip(request.timeline, spans(request.timeline))]


def floor_contact(joints: np.ndarray) -> dict:
    """``lowest_m`` (the lowest joint's lowest height over the clip, m), ``touches_floor`` (some joint comes within
    :data:`simdiff.motion.metrics.FLOOR_CLEARANCE` of y = 0; :func:`simdiff.motion.metrics.never_touches`) and
    ``glides`` (the body travels while no foot ever lifts; :func:`simdiff.motion.metrics.glides`)."""
    from simdiff.motion.metrics import glides, never_touches

    return {"lowest_m": round(float(np.asarray(joints)[..., 1].min()), 4),
            "touches_floor": not bool(never_touches(joints)[0]), "glides": bool(glides(joints)[0])}


def _simulated_summary(sim: SimulatedMotion) -> dict:
    """The tracking result's headline numbers for ``generation.json``."""
    t = sim.tracking
    keys = ("success", "status", "fall_frame", "n_frames", "n_out", "err_mm", "err_local_mm", "d_l2", "time_warp",
            "wall_s", "cpu_s", "env_assumed", "attempts", "fallback")
    return {**{k: t.get(k) for k in keys}, "physics_simulated": t.get("physics_simulated")}


def normalizer_of(generator) -> object | None:
    """The generator's feature statistics as a :class:`~simdiff.motion.normalize.Normalizer` (None if unusable)."""
    from simdiff.errors import SimdiffError
    from simdiff.motion.normalize import Normalizer

    try:
        return Normalizer(generator.mean.detach().cpu().numpy(), generator.std.detach().cpu().numpy())
    except (SimdiffError, AttributeError):
        return None


def simulate_samples(generator, samples: list[Sample], timer: Timer, force: bool = False,
                     finisher: Finisher | None = None) -> None:
    """Re-track every sample under its φ (:func:`simdiff.product.simulate.simulate_finish`), in place:
    in ``finisher``'s worker processes when given, else here."""
    norm = normalizer_of(generator)
    with timer.stage("simulate"):
        if finisher is None:
            for s in samples:
                s.simulated = simulate_finish(s.joints, s.env, normalizer=norm, force=force)
            return
        futures = [finisher.submit(s.joints, s.env, norm, force) for s in samples]
        for s, future in zip(samples, futures):
            s.simulated = finisher.result(future)


def warm_simulator() -> threading.Thread:
    """Start loading MuJoCo, scipy and the humanoid (about 1 CPU-s) on a thread while the diffusion samples:
    sampling runs mostly in torch's native code, so the imports use the time it leaves (measured: 0.4–1.0 s
    less wall time per ``--simulate`` command on 2 cores). Used when the finish runs in this process (one
    CPU, ``SIMDIFF_FINISH_WORKERS=0``, the viewer); ``simdiff generate`` otherwise starts a
    :class:`~simdiff.product.finisher.Finisher` process, which hides the imports entirely."""
    thread = threading.Thread(target=load_simulator, name="simdiff-warm-simulator", daemon=True)
    thread.start()
    return thread


def previous_outputs(out_dir: Path) -> set[str]:
    """Names of the files an earlier ``generate`` listed in ``out_dir/generation.json`` (none when unreadable): a new
    run into the same folder removes those it does not replace, so the folder holds one run."""
    import json

    try:
        meta = json.loads((out_dir / "generation.json").read_text(encoding="utf-8"))
        names = {n for rec in meta["samples"] for n in rec["files"].values()} | set(meta.get("videos", []))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return set()
    return {n for n in names if isinstance(n, str) and n == Path(n).name and not n.startswith(".")}


def run_generation(generator, request: GenerationRequest, out_dir: Path, model_dir: Path, timer: Timer,
                   quiet: bool = False, simulate: bool = False,
                   force: bool = False, finisher: Finisher | None = None,
                   coverage: list[PromptCoverage] | None = None) -> tuple[dict, list[Path]]:
    """Sample (and with ``simulate`` re-track under φ: in ``finisher``'s processes when given, which
    should have been started before the model loaded), write every file and ``generation.json`` (with
    ``coverage``, :func:`prompt_coverage`'s answer, when given); returns (metadata, written paths in print order)."""
    warm = warm_simulator() if simulate and finisher is None else None
    failure: SimdiffError | None = None
    samples = sample_motions(generator, request, timer, quiet)
    if simulate:
        if warm is not None:
            warm.join()
        try:
            simulate_samples(generator, samples, timer, force, finisher)
        except SimdiffError as exc:  # the generated motions are written all the same, then the error is raised
            failure = exc
    earlier = previous_outputs(out_dir)
    with output_set(out_dir, last="generation.json") as stage:  # every file appears together, or none
        files, videos = write_outputs(samples, request, stage, timer, quiet)
        meta = metadata(request, generator, model_dir, samples, files, videos, timer, coverage)
        if simulate:  # where the finish ran: its CPU seconds are the worker's (in each sample's tracking)
            meta["simulate_workers"] = finisher.workers if finisher is not None else 0
        if failure is not None:
            meta["simulate_error"] = str(failure)
        write_metadata(stage / "generation.json", meta)
    meta_path = out_dir / "generation.json"
    files = [{kind: out_dir / p.name for kind, p in written.items()} for written in files]
    videos = [out_dir / p.name for p in videos]
    for name in earlier - {p.name for written in files for p in written.values()} - {p.name for p in videos}:
        (out_dir / name).unlink(missing_ok=True)  # an earlier run's samples that this run did not replace
    if failure is not None:
        raise SimdiffError(f"{failure} (the generated motions and generation.json are written in {out_dir})")
    paths = {p for written in files for p in written.values()} | set(videos)
    return meta, sorted(paths, key=lambda p: p.name) + [meta_path]
