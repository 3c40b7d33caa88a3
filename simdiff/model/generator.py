"""Inference-only text-to-motion model: network + text encoder + normaliser + sampler.

The trainer (:mod:`simdiff.train`) owns optimisers and data; this class only loads, samples
and saves. Weights: ``model.safetensors`` + ``config.json``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Sequence

import torch
from torch import Tensor, nn

from simdiff.diffusion.guidance import ANCHORS, REFERENCE_ENV, check_anchor_alpha, check_anchor_t_max, check_edit_t
from simdiff.diffusion.sampling import X0Hook, make_scheduler, sample
from simdiff.errors import SimdiffError
from simdiff.model.checkpoint import load_pretrained, save_pretrained
from simdiff.model.condition import Condition
from simdiff.model.config import ModelConfig
from simdiff.motion.skeleton import MAX_FRAMES


@dataclass
class Generation:
    """Sampled motions.

    Attributes:
        features: (B, T, 263) un-normalised features, zero beyond each length.
        normalized: (B, T, 263) the raw sampler output (normalised space).
        lengths: (B,) int64 valid frames per motion.
    """

    features: Tensor
    normalized: Tensor
    lengths: Tensor
    fell_back: Tensor | None = None
    """(B,) bool: the rows re-sampled at ``env_guidance_fallback`` (None when no fallback was asked for)."""

    def clips(self) -> list[Tensor]:
        """Un-normalised features cut to each length: list of (L_i, 263)."""
        return [f[: int(n)] for f, n in zip(self.features, self.lengths)]


class MotionGenerator:
    """Generate motions from captions (and φ for SimDiff models).

    Args:
        network: an ``MDMBackbone`` or ``SimDiffNet`` (put in eval mode, gradients off).
        config: its :class:`ModelConfig`.
        text_encoder: anything with ``encode(list[str]) -> (B, text_dim)``; None for pre-encoded use.
        mean, std: (263,) feature statistics used to un-normalise (defaults 0 and 1).
        device: where the network runs.
    """

    def __init__(self, network: nn.Module, config: ModelConfig, text_encoder: object | None = None,
                 mean: Tensor | None = None, std: Tensor | None = None, device: torch.device | str = "cpu") -> None:
        self.device = torch.device(device)
        self.network = network.to(self.device).eval().requires_grad_(False)
        self.config = config
        self.text_encoder = text_encoder
        n = config.backbone.nfeats
        self.mean = (mean if mean is not None else torch.zeros(n)).float().to(self.device)
        self.std = (std if std is not None else torch.ones(n)).float().to(self.device)

    @classmethod
    def load(cls, folder: str | os.PathLike[str], device: torch.device | str = "cpu", text_weights: str | None = None,
             load_text: bool = True) -> "MotionGenerator":
        """Load a model folder and (unless ``load_text`` is False) its text encoder."""
        network, config, extra = load_pretrained(folder, device)
        encoder = None
        if load_text:
            from simdiff.text.base import load_text_encoder

            encoder = load_text_encoder(config.text_encoder, device, text_weights)
        return cls(network, config, encoder, extra.get("normalizer.mean"), extra.get("normalizer.std"), device)

    def save(self, folder: str | os.PathLike[str]) -> None:
        """Write ``model.safetensors`` (weights + normaliser) and ``config.json``."""
        save_pretrained(folder, self.network, self.config, {"normalizer.mean": self.mean, "normalizer.std": self.std})

    @property
    def is_simdiff(self) -> bool:
        return self.config.sim is not None

    def encode_text(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, text_dim) on this device."""
        if self.text_encoder is None:
            raise SimdiffError("this generator was loaded without a text encoder")
        return self.text_encoder.encode(list(texts)).float().to(self.device)  # type: ignore[attr-defined]

    @torch.no_grad()
    def generate(
        self,
        texts: Sequence[str],
        lengths: int | Sequence[int] = 120,
        *,
        env: Sequence[float] | Tensor | None = None,
        env_index: int | Sequence[int] | Tensor | None = None,
        alpha: float = 1.0,
        sampler: str = "ddim",
        steps: int | None = None,
        eta: float = 0.0,
        guidance: float = 2.5,
        seed: int | None = 0,
        batched_cfg: bool = True,
        text_embeddings: Tensor | None = None,
        x0_hook: X0Hook | None = None,
        hook_timesteps: Iterable[int] | None = None,
        progress: Callable[[Iterable[Tensor]], Iterable[Tensor]] | None = None,
        foot_lock: float = 0.0,
        env_guidance: float = 1.0,
        anchor: str = "adapters",
        env_guidance_fallback: float | None = None,
        anchor_alpha: float = 0.0,
        anchor_t_max: int | None = None,
        ballistic: float = 0.0,
        edit_t: int | None = None,
    ) -> Generation:
        """Sample one motion per caption.

        Args:
            texts: B captions.
            lengths: frames per motion (one int for all, or B ints), each in [1, 196].
            env: φ = (g_z, w_x, w_y) as (3,) for all or (B, 3); SimDiff continuous models.
            env_index: environment category (int or B ints); SimDiff categorical models.
            alpha: adapter strength (0 = backbone only).
            sampler: ``ddim`` (default 50 steps) or ``ddpm`` (default 1000).
            guidance: CFG scale s (1 = off); conditional and unconditional passes batched when ``batched_cfg``.
            seed: noise seed (None: nondeterministic).
            text_embeddings: (B, text_dim) precomputed text vectors instead of encoding ``texts``.
            x0_hook, hook_timesteps: replace x̂₀ at chosen t (PhysDiff projection).
            foot_lock: strength in [0, 1] of :func:`simdiff.motion.foot_lock.clean_feet` applied to the final
                sample (0: off): the root is moved so the joints the sample marks in contact do not slide, then
                swinging feet that drag along the floor are lifted 2 cm clear of it (knee re-solved).
            env_guidance: s_e ≥ 0 (1 = off): the adapters' answer to φ against Earth without wind is pushed s_e
                times as far (:mod:`simdiff.diffusion.guidance`); continuous SimDiff models only. Motions under
                Earth without wind are unchanged; the others cost one more network pass per step.
            env_guidance_fallback: s_e for the samples that come out physically impossible at ``env_guidance`` (their
                raw output never comes within 0.10 m of the floor, or glides: :func:`simdiff.motion.metrics.glides`);
                the batch is sampled again with the same seed at this s_e and those rows replaced (None: off).
            anchor: ``"adapters"`` (default) or ``"backbone"``: the text guidance runs on the backbone alone and only
                the adapters' answer to φ against Earth without wind (times s_e) is added, so motions under Earth
                without wind are the backbone's (:mod:`simdiff.diffusion.guidance`); continuous SimDiff models only.
                ``"reference"``: the text guidance runs under Earth without wind with the adapters at
                ``anchor_alpha`` and the adapters anchor's own answer to φ (text guidance and s_e included) is added.
                ``"edit"``: a motion under another gravity than Earth's is its Earth-without-wind motion (the
                reference anchor) until the step ``edit_t``, then continues under its φ with the adapters anchor;
                every other motion is the reference anchor's (wind alone included).
            anchor_alpha: with ``anchor="backbone"``, ``"reference"`` or ``"edit"``, the adapter strength its text guidance runs
                at (0: the backbone alone; e.g. 0.25: motions under Earth without wind are those of α 0.25, the
                answer to φ is α's).
            anchor_t_max: with ``anchor="backbone"`` or ``"reference"``, that anchor only at the denoising steps
                whose timestep is ≤ this (0..999), the adapters anchor at the earlier ones (None: every step).
            ballistic: strength in [0, 1] of :func:`simdiff.motion.ballistic.ballistic_flights` applied after the foot
                cleanup (0: off): every flight's pelvis height follows the parabola of the sample's gravity (φ's g_z;
                Earth for a backbone-only model), the whole body moved with it; not for categorical SimDiff models.
            edit_t: with ``anchor="edit"``, the last timestep (0..999) at which motions under another gravity
                still follow their Earth motion (None: :data:`simdiff.diffusion.guidance.DEFAULT_EDIT_T`).
        """
        b = len(texts) if text_embeddings is None else int(text_embeddings.shape[0])
        if b == 0:
            raise SimdiffError("no text given")
        lens = torch.tensor([lengths] * b if isinstance(lengths, int) else list(lengths), dtype=torch.long)
        if lens.numel() != b:
            raise SimdiffError(f"got {lens.numel()} lengths for {b} texts")
        bad = [int(n) for n in lens if not 1 <= int(n) <= MAX_FRAMES]
        if bad:
            raise SimdiffError(f"motion length must be 1..{MAX_FRAMES} frames (9.8 s at 20 fps), got {bad[0]}")
        continuous = self.config.sim is not None and self.config.sim.mode == "continuous"
        env_guidance = float(env_guidance)
        if env_guidance != 1.0:
            if not (env_guidance >= 0.0 and env_guidance < float("inf")):
                raise SimdiffError(f"env guidance must be a finite number ≥ 0, got {env_guidance}")
            if not continuous:
                raise SimdiffError("env guidance needs a SimDiff model with a continuous Sim Encoder; "
                                   "this model has none (leave it at 1)")
        if env_guidance_fallback is not None:
            env_guidance_fallback = float(env_guidance_fallback)
            if not (env_guidance_fallback >= 0.0 and env_guidance_fallback < float("inf")):
                raise SimdiffError(f"env guidance fallback must be a finite number ≥ 0, got {env_guidance_fallback}")
            if not continuous:
                raise SimdiffError("env guidance fallback needs a SimDiff model with a continuous Sim Encoder")
        if anchor not in ANCHORS:
            raise SimdiffError(f"unknown guidance anchor {anchor!r}; choose one of {', '.join(ANCHORS)}")
        if anchor != "adapters" and not continuous:
            raise SimdiffError(f"anchor {anchor!r} needs a SimDiff model with a continuous Sim Encoder; "
                               "this model has none (leave it at 'adapters')")
        anchor_alpha = check_anchor_alpha(anchor_alpha, anchor)
        anchor_t_max = check_anchor_t_max(anchor_t_max, anchor)
        edit_t = check_edit_t(edit_t, anchor)
        ballistic = check_ballistic(ballistic, self.config)
        # options checked first: a bad one fails before the text encoder runs
        text = text_embeddings.float().to(self.device) if text_embeddings is not None else self.encode_text(texts)
        frames = int(lens.max())
        mask = (torch.arange(frames)[None] < lens[:, None]).to(self.device)
        cond = Condition(text=text, frame_mask=mask, alpha=float(alpha), **self._env(b, env, env_index))
        def run(push: float) -> Tensor:
            generator = None if seed is None else torch.Generator(device=self.device).manual_seed(int(seed))
            return sample(self.network, make_scheduler(sampler, steps, eta), cond, frames,
                          nfeats=self.config.backbone.nfeats, guidance=guidance, batched_cfg=batched_cfg,
                          generator=generator, x0_hook=x0_hook, hook_timesteps=hook_timesteps, progress=progress,
                          env_guidance=push, anchor=anchor, anchor_alpha=anchor_alpha, anchor_t_max=anchor_t_max,
                          edit_t=edit_t)

        x = run(env_guidance)
        fell_back = None
        if env_guidance_fallback is not None:
            fell_back = torch.zeros(b, dtype=torch.bool, device=x.device)  # the same s_e: nothing to re-sample
            if env_guidance_fallback != env_guidance:
                fell_back = impossible(x * self.std + self.mean, lens).to(x.device)
                if bool(fell_back.any()):
                    x = torch.where(fell_back[:, None, None], run(env_guidance_fallback), x)
        features = (x * self.std + self.mean) * mask[..., None]
        if foot_lock and frames >= 2:  # one frame has no step to correct
            from simdiff.motion.foot_lock import clean_feet

            features = clean_feet(features, lens, foot_lock) * mask[..., None]
            x = torch.where(mask[..., None], (features - self.mean) / self.std, x)
        if ballistic and frames >= 3:  # a flight needs a take-off frame and two in the air
            from simdiff.motion.ballistic import ballistic_flights

            gravity = cond.env[:, 0] if cond.env is not None else REFERENCE_ENV[0]
            features = ballistic_flights(features, gravity, lens, ballistic) * mask[..., None]
            x = torch.where(mask[..., None], (features - self.mean) / self.std, x)
        return Generation(features=features, normalized=x, lengths=lens, fell_back=fell_back)

    def _env(self, b: int, env: Sequence[float] | Tensor | None,
             env_index: int | Sequence[int] | Tensor | None) -> dict[str, Tensor | None]:
        """Validate φ against the model kind and broadcast it to the batch."""
        sim = self.config.sim
        if sim is None:
            if env is not None or env_index is not None:
                raise SimdiffError("this is a backbone-only model: it takes no environment (φ); load a SimDiff model")
            return {}
        if sim.mode == "continuous":
            if env is None:
                env = (-9.81, 0.0, 0.0)
            phi = torch.as_tensor(env, dtype=torch.float32)
            if phi.numel() % 3 or phi.reshape(-1, 3).shape[0] not in (1, b):
                raise SimdiffError(f"env must be 3 numbers or {b}×3, got shape {tuple(phi.shape)}")
            return {"env": phi.reshape(-1, 3).expand(b, 3).to(self.device)}
        if env_index is None:
            raise SimdiffError("this SimDiff model is categorical: give an environment index (--env-index)")
        idx = torch.as_tensor(env_index, dtype=torch.long).reshape(-1)
        if idx.shape[0] not in (1, b):
            raise SimdiffError(f"env_index must be 1 or {b} integers")
        return {"env_index": idx.expand(b).to(self.device)}


def check_ballistic(value: float, config: ModelConfig) -> float:
    """``value`` as a float in [0, 1] usable with ``config``'s model; a one-line :class:`SimdiffError` otherwise."""
    value = float(value)
    if not 0.0 <= value <= 1.0:
        raise SimdiffError(f"ballistic strength must be in [0, 1], got {value}")
    if value and config.sim is not None and config.sim.mode != "continuous":
        raise SimdiffError("ballistic flight needs gravity as a number: a continuous SimDiff model or a backbone-only "
                           "one, not a categorical SimDiff model (leave it at 0)")
    return value


def impossible(features: Tensor, lengths: Tensor) -> Tensor:
    """(B,) bool: raw samples no body could perform — never within 0.10 m of the floor, or gliding (the pelvis
    travels while no foot joint lifts; :mod:`simdiff.motion.metrics`). Features (B, T, 263) un-normalised; clips
    under 2 frames are never flagged."""
    from simdiff.motion.features import features_to_joints
    from simdiff.motion.metrics import glides, never_touches

    out = torch.zeros(len(lengths), dtype=torch.bool)
    rows = [i for i, n in enumerate(lengths.tolist()) if n >= 2]
    if rows:
        joints = features_to_joints(features[rows].detach().double().cpu()).numpy()
        lens = lengths[rows].cpu().numpy()
        out[rows] = torch.from_numpy(never_touches(joints, lens) | glides(joints, lens))
    return out


def guidance_kwargs(env_guidance: float = 1.0, anchor: str = "adapters", anchor_alpha: float = 0.0,
                    anchor_t_max: int | None = None, env_guidance_fallback: float | None = None,
                    ballistic: float = 0.0, edit_t: int | None = None) -> dict[str, Any]:
    """The environment-guidance and anchor keywords of :meth:`MotionGenerator.generate` that differ from its
    defaults: callers pass only these, so wrappers (PhysDiff's) and test stand-ins need not know them all."""
    out: dict[str, Any] = {}
    if env_guidance != 1.0:
        out["env_guidance"] = env_guidance
    if anchor != "adapters":
        out["anchor"] = anchor
    if anchor_alpha:
        out["anchor_alpha"] = anchor_alpha
    if anchor_t_max is not None:
        out["anchor_t_max"] = anchor_t_max
    if env_guidance_fallback is not None:
        out["env_guidance_fallback"] = env_guidance_fallback
    if ballistic:
        out["ballistic"] = ballistic
    if edit_t is not None:
        out["edit_t"] = edit_t
    return out
