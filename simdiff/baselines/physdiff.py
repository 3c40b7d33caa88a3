"""PhysDiff (Yuan et al. 2023) on our diffusion models: simulator projection of x̂₀ at chosen steps.

At each scheduled timestep t the sampler's x̂₀ prediction (normalised features) is

1. un-normalised and turned into joints (``features_to_joints`` + the last frame rebuilt by
   ``extend_last_frame``: L feature rows → L+1 joint frames);
2. projected by the simulator under φ (:func:`simdiff.sim.project`: PD tracking in MuJoCo);
3. re-encoded as §4.3 of the facts file prescribes: rollout joints → ``process_joints``
   (canonical skeleton; by default *no* floor re-normalisation, so the simulator's ground
   contact is kept) → L feature rows → normalised;
4. substituted for x̂₀, and the step forms x_{t−1} from it (DDIM: ε̂ from x_t and the
   projected x̂₀; DDPM: the posterior mean), see :mod:`simdiff.diffusion.sampling`.

Schedule (facts §5): PhysDiff's best "End4/Space1" projects on the last four DDIM-50 steps,
which in original timestep indices are t = 60, 40, 20, 0; with DDPM-1000 we project at the
same original t = 60, 40, 20, 0. At t = 0 the projected motion is the output.

When a rollout falls, the frames it returned replace the prediction and the rest keep the
model's x̂₀ (the tracker gives no state beyond a fall); padding frames are never touched.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Iterable

import numpy as np
import torch
from torch import Tensor

from simdiff.diffusion.config import SAMPLER_STEPS, SamplingConfig
from simdiff.diffusion.sampling import make_scheduler
from simdiff.errors import SimdiffError
from simdiff.motion.normalize import Normalizer
from simdiff.sim.env import Environment
from simdiff.sim.pool import Projector

PHYSDIFF_TIMESTEPS: tuple[int, ...] = (60, 40, 20, 0)
"""End4/Space1 in original timestep indices (the last four DDIM-50 steps)."""


@dataclass
class PhysDiffConfig:
    """Options of the PhysDiff sampler.

    Attributes:
        sampler: ``ddim`` (default 50 steps) or ``ddpm`` (default 1000).
        steps: sampling steps (None: the sampler's default).
        project_at: original timesteps whose x̂₀ is projected (default 60, 40, 20, 0).
        env: φ the simulator projects under (g_z m/s², w_x N, w_y N).
        residual_bound: tracker root-residual bound (fraction of m·|g_z|; 0 = strict).
        refloor: re-floor the rollout (min y = 0) when re-encoding; False keeps the sim's floor.
        guidance: classifier-free guidance scale.
        workers, backend: default projector's parallelism (``serial``, ``process``, ``ray``).
    """

    sampler: str = "ddim"
    steps: int | None = None
    project_at: tuple[int, ...] = PHYSDIFF_TIMESTEPS
    env: tuple[float, float, float] = (-9.81, 0.0, 0.0)
    residual_bound: float = 0.5
    refloor: bool = False
    guidance: float = 2.5
    workers: int = 1
    backend: str = "serial"


def end_schedule(timesteps: Sequence[int], count: int = 4, space: int = 1) -> list[int]:
    """PhysDiff's "End{count}/Space{space}": ``count`` of the last sampling steps, ``space`` apart.

    Args:
        timesteps: the sampler's timesteps in sampling (descending) order.
    Returns:
        Original timestep indices, descending (DDIM-50: [60, 40, 20, 0]).
    """
    ts = [int(t) for t in timesteps]
    if count < 1 or space < 1 or (count - 1) * space >= len(ts):
        raise SimdiffError(f"cannot place {count} projections {space} apart in {len(ts)} steps")
    return ts[len(ts) - 1 - (count - 1) * space :: space]


def check_schedule(sampler: str, steps: int | None, project_at: Iterable[int]) -> list[int]:
    """The projection timesteps, checked to be steps of the sampler; descending."""
    kept = {int(t) for t in make_scheduler(sampler, steps).timesteps}
    at = sorted({int(t) for t in project_at}, reverse=True)
    bad = [t for t in at if t not in kept]
    if bad:
        raise SimdiffError(f"projection timestep {bad[0]} is not a step of {sampler} with {steps or 'default'} steps")
    return at


def reencode(rollout: np.ndarray, refloor: bool = False) -> np.ndarray:
    """(n, 22, 3) rollout joints → (n−1, 263) float32 features (canonical skeleton)."""
    from simdiff.motion.features import process_joints

    return process_joints(np.asarray(rollout, dtype=np.float64), canonical=refloor).features.astype(np.float32)


def _info_field(info: Any, name: str, default: Any) -> Any:
    """A field of a projector's per-motion info: a dict, a :class:`~simdiff.sim.project.ProjectionInfo`, or an
    error string (``default``)."""
    return info.get(name, default) if isinstance(info, dict) else getattr(info, name, default)


@dataclass
class ProjectionHook:
    """The x̂₀ hook ``(x0 (B,T,263) normalised, t, x_t) -> x0'`` that projects through the simulator.

    Args:
        normalizer: the model's feature statistics.
        lengths: (B,) valid frames per sample.
        envs: one φ per sample (or one for all).
        projector: ``(joints list, env list) -> iterable of (rollout | None, info)``.
        refloor: see :class:`PhysDiffConfig`.
    Attributes:
        log: one entry per projection call: t, per-sample success/frames/rollouts simulated/whether the
            fallback's rollout was kept (:mod:`simdiff.sim.fallback`), wall seconds.
    """

    normalizer: Normalizer
    lengths: Sequence[int]
    envs: Sequence[Environment] | Environment
    projector: Projector
    refloor: bool = False
    log: list[dict[str, Any]] = field(default_factory=list)

    def __call__(self, x0: Tensor, t: int, x_t: Tensor) -> Tensor:
        from simdiff.motion.features import extend_last_frame, features_to_joints

        start = time.perf_counter()
        b = x0.shape[0]
        if len(self.lengths) != b:
            raise SimdiffError(f"{len(self.lengths)} lengths for a batch of {b}")
        envs = [self.envs] * b if isinstance(self.envs, Environment) else list(self.envs)
        raw = self.normalizer.denormalize(x0.detach().float().cpu()).numpy().astype(np.float64)
        motions = []
        for i in range(b):
            f = raw[i, : int(self.lengths[i])]
            motions.append(extend_last_frame(np.asarray(features_to_joints(f)), f))
        out = x0.detach().clone()
        entries = []
        for i, (rollout, info) in enumerate(self.projector(motions, envs)):
            n_rows = 0
            if rollout is not None and len(rollout) >= 2:
                feats = reencode(rollout, self.refloor)
                n_rows = min(len(feats), int(self.lengths[i]))
                sub = self.normalizer.normalize(torch.from_numpy(feats[:n_rows]))
                out[i, :n_rows] = sub.to(out.device, out.dtype)
            entries.append({"success": bool(_info_field(info, "success", False)), "frames_replaced": n_rows,
                            "attempts": int(_info_field(info, "attempts", 1)),
                            "fallback": bool(_info_field(info, "fallback", False)),
                            "error": info if isinstance(info, str) else None})
        self.log.append({"t": int(t), "samples": entries, "wall_s": time.perf_counter() - start})
        return out


def default_projector(config: PhysDiffConfig) -> Projector:
    """Simulator projector with the config's residual bound and parallelism."""
    from simdiff.data.augment.projector import SimProjector

    return SimProjector(None, config.workers, config.backend, config.residual_bound)


def physdiff_generate(generator: Any, texts: Sequence[str], lengths: int | Sequence[int],
                      config: PhysDiffConfig = PhysDiffConfig(), *, projector: Projector | None = None, seed: int | None = 0,
                      sampling: SamplingConfig = SamplingConfig(), env: Sequence[float] | None = None,
                      env_index: int | None = None) -> tuple[Any, ProjectionHook]:
    """Sample with PhysDiff projection.

    Args:
        generator: a :class:`simdiff.inference.generator.MotionGenerator` (backbone or SimDiff).
        texts, lengths: as ``MotionGenerator.generate``.
        config: see :class:`PhysDiffConfig`; its sampler, steps and guidance replace ``sampling``'s (η 0, no foot
            lock and no flight guidance: the projection is the only physics step).
        projector: injected projector (tests); default the MuJoCo tracker.
        sampling: the generator's other settings (α, environment guidance, ``edit_t``).
        env, env_index: φ or the environment category, as ``MotionGenerator.generate``.
    Returns:
        (the :class:`simdiff.inference.generator.Generation`, the hook with its per-call log).
    """
    at = check_schedule(config.sampler, config.steps, config.project_at)
    b = len(texts)
    lens = [int(lengths)] * b if isinstance(lengths, int) else [int(n) for n in lengths]
    normalizer = Normalizer(generator.mean.cpu().numpy(), generator.std.cpu().numpy())
    own = projector is None
    proj = projector or default_projector(config)
    hook = ProjectionHook(normalizer, lens, Environment(*config.env).validate(), proj, config.refloor)
    try:
        run = replace(sampling, sampler=config.sampler, steps=config.steps or SAMPLER_STEPS[config.sampler], eta=0.0,
                      guidance=config.guidance, foot_lock=0.0, flight_passes=0)
        generation = generator.generate(texts, lens, run, env=env, env_index=env_index, seed=seed, x0_hook=hook,
                                        hook_timesteps=at)
    finally:
        if own:
            getattr(proj, "close", lambda: None)()
    return generation, hook
