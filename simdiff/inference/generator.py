"""Inference-only text-to-motion model: network + text encoder + normaliser + sampler.

The trainer (:mod:`simdiff.train`) owns optimisers and data; this class only loads, samples
and saves. Weights: ``model.safetensors`` + ``config.json``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable, Iterable, Sequence

import torch
from torch import Tensor, nn

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.guidance import REFERENCE_ENV
from simdiff.diffusion.sampling import X0Hook, sample
from simdiff.errors import NonFiniteResult, SimdiffError
from simdiff.model.checkpoint import load_pretrained, save_pretrained
from simdiff.model.condition import Condition
from simdiff.model.config import ModelConfig
from simdiff.motion.skeleton import MAX_FRAMES, MIN_GENERATE_FRAMES


EMBEDDING_CACHE: int = 256
"""Single prompts whose text embedding a generator keeps (oldest dropped first)."""


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
        self._embedded: dict[str, Tensor] = {}  # one prompt at a time (generate, the viewer): its embedding
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
    def text_encoder(self) -> object | None:
        """The text encoder (``encode(list[str]) -> (B, text_dim)``); setting another forgets the cached embeddings."""
        return self._text_encoder

    @text_encoder.setter
    def text_encoder(self, encoder: object | None) -> None:
        self._text_encoder = encoder
        self._embedded.clear()

    @property
    def is_simdiff(self) -> bool:
        return self.config.sim is not None

    def encode_text(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, text_dim) on this device."""
        if self.text_encoder is None:
            raise SimdiffError("this generator was loaded without a text encoder")
        texts = list(texts)
        if len(texts) != 1 or EMBEDDING_CACHE < 1:  # batches are encoded whole: padding makes a caption's numbers depend on its batch
            return self.text_encoder.encode(texts).float().to(self.device)  # type: ignore[attr-defined]
        if texts[0] not in self._embedded:  # a viewer dragging sliders asks for one prompt again and again
            while len(self._embedded) >= EMBEDDING_CACHE:
                self._embedded.pop(next(iter(self._embedded)))
            self._embedded[texts[0]] = self.text_encoder.encode(texts).float().to(self.device)  # type: ignore
        return self._embedded[texts[0]].clone()

    @torch.no_grad()
    def generate(
        self,
        texts: Sequence[str],
        lengths: int | Sequence[int] = 120,
        config: SamplingConfig = SamplingConfig(),
        *,
        env: Sequence[float] | Tensor | None = None,
        env_index: int | Sequence[int] | Tensor | None = None,
        seed: int | None = 0,
        batched_cfg: bool = True,
        text_embeddings: Tensor | None = None,
        x0_hook: X0Hook | None = None,
        hook_timesteps: Iterable[int] | None = None,
        progress: Callable[[Iterable[Tensor]], Iterable[Tensor]] | None = None,
    ) -> Generation:
        """Sample one motion per caption.

        Args:
            texts: B captions.
            lengths: frames per motion (one int for all, or B ints), each in [10, 196].
            config: the sampling configuration (:mod:`simdiff.diffusion.guidance` for how φ enters); its
                ``foot_lock`` > 0 applies :func:`simdiff.motion.foot_lock.clean_feet` to the final sample.
            env: φ = (g_z, w_x, w_y) as (3,) for all or (B, 3); SimDiff continuous models.
            env_index: environment category (int or B ints); SimDiff categorical models.
            seed: noise seed in 0..2⁶³−1 (None: nondeterministic).
            batched_cfg: the conditional and unconditional passes as one batched forward.
            text_embeddings: (B, text_dim) precomputed text vectors instead of encoding ``texts``.
            x0_hook, hook_timesteps: replace x̂₀ at chosen t (PhysDiff projection); with ``config.flight_passes``
                the flight guidance follows it (:mod:`simdiff.inference.flight_guidance`).
            progress: optional iterable wrapper of the timesteps (e.g. ``tqdm``).
        """
        b = len(texts) if text_embeddings is None else int(text_embeddings.shape[0])
        if b == 0:
            raise SimdiffError("no text given")
        lens = torch.tensor([lengths] * b if isinstance(lengths, int) else list(lengths), dtype=torch.long)
        if lens.numel() != b:
            raise SimdiffError(f"got {lens.numel()} lengths for {b} texts")
        bad = [int(n) for n in lens if not MIN_GENERATE_FRAMES <= int(n) <= MAX_FRAMES]
        if bad:
            raise SimdiffError(f"motion length must be {MIN_GENERATE_FRAMES}..{MAX_FRAMES} frames (0.5..9.8 s at "
                               f"20 fps), got {bad[0]}")
        if seed is not None and not 0 <= int(seed) < 2**63:  # torch.Generator's range
            raise SimdiffError(f"seed must be in 0..2**63-1, got {seed}")
        continuous = self.config.sim is not None and self.config.sim.mode == "continuous"
        if config.env_guidance != 1.0 and not continuous:
            raise SimdiffError("--env-guidance needs a SimDiff model with a continuous Sim Encoder; "
                               "this model has none (leave it at 1)")
        # options checked first: a bad one fails before the text encoder runs
        text = text_embeddings.float().to(self.device) if text_embeddings is not None else self.encode_text(texts)
        frames = int(lens.max())
        mask = (torch.arange(frames)[None] < lens[:, None]).to(self.device)
        cond = Condition(text=text, frame_mask=mask, alpha=config.alpha, **self._env(b, env, env_index))
        generator = None if seed is None else torch.Generator(device=self.device).manual_seed(int(seed))
        if config.flight_passes:
            from simdiff.inference.flight_guidance import with_flight_guidance

            if cond.env_index is not None:
                raise SimdiffError("--flight-passes needs the gravity as a number (a continuous SimDiff model or a "
                                   "backbone); this model takes an environment category (set it to 0)")
            gravity = cond.env[:, 0].tolist() if cond.env is not None else [REFERENCE_ENV[0]] * b
            x0_hook = with_flight_guidance(x0_hook, hook_timesteps, config, gravity, self.mean, self.std,
                                           lens.tolist())
            hook_timesteps = None
        x = sample(self.network, config, cond, frames, nfeats=self.config.backbone.nfeats, batched_cfg=batched_cfg,
                   generator=generator, x0_hook=x0_hook, hook_timesteps=hook_timesteps, progress=progress)
        features = (x * self.std + self.mean) * mask[..., None]
        _check_finite(features, config, env)
        if config.foot_lock:
            from simdiff.motion.foot_lock import clean_feet

            features = clean_feet(features, lens, config.foot_lock) * mask[..., None]
            _check_finite(features, config, env)
            x = torch.where(mask[..., None], (features - self.mean) / self.std, x)
        return Generation(features=features, normalized=x, lengths=lens)

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



def _check_finite(features: Tensor, config: SamplingConfig, env: object) -> None:
    """Refuse a sample with nan or inf (extreme guidance or φ): callers write nothing of it."""
    if not bool(torch.isfinite(features).all()):
        phi = "" if env is None else f", φ {[round(float(v), 4) for v in torch.as_tensor(env).flatten()[:3]]}"
        raise NonFiniteResult(f"sampling gave non-finite values (guidance {config.guidance:g}, alpha {config.alpha:g}, "
                           f"env guidance {config.env_guidance:g}{phi}); try settings nearer the model's defaults")
