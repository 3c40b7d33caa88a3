"""``simdiff sample``: sample motions from a trained model folder (backbone or SimDiff)."""

from __future__ import annotations

import argparse
from dataclasses import fields
from pathlib import Path

from simdiff.cli.options import SEED, integer, real
from simdiff.diffusion.config import (ALPHA_RANGE, ENV_GUIDANCE_RANGE, GUIDANCE_RANGE, MAX_FLIGHT_PASSES, MAX_STEPS,
                                      SAMPLERS, SamplingConfig)
from simdiff.motion.skeleton import MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.sim.env import MAX_FORCED_WIND

MAX_MOTIONS: int = 1024
"""Most motions one ``simdiff sample`` run makes (captions × ``--batch``)."""
CHUNK: int = 32
"""Motions sampled at once: memory stays that of 32 motions whatever ``--batch`` is."""


_ENV = real(-MAX_FORCED_WIND, MAX_FORCED_WIND)
"""``--env`` values: finite and within the widest wind bound; gravity's own range is checked with φ."""


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "sample",
        help="sample motions from a trained model (text, length, gravity/wind, sampler, guidance)",
        description="Sample motions with DDPM or DDIM and classifier-free guidance from a model folder "
                    "(model.safetensors + config.json). Writes features (T, 263) and joints (T, 22, 3) as .npy.",
    )
    p.add_argument("--model", type=Path, required=True, help="model folder, e.g. runs/backbone/model")
    p.add_argument("--text", action="append", required=True, help="caption (repeat for several)")
    p.add_argument("--length", type=integer(MIN_GENERATE_FRAMES, MAX_FRAMES), default=120,
                   help=f"frames at 20 fps, {MIN_GENERATE_FRAMES}..{MAX_FRAMES} (default 120 = 6 s)")
    p.add_argument("--env", type=_ENV, nargs=3, metavar=("G_Z", "W_X", "W_Y"),
                   help="φ for SimDiff models: gravity m/s² and wind N (default -9.81 0 0)")
    p.add_argument("--env-index", type=integer(0, 1023), help="environment category for categorical SimDiff models")
    smp = p.add_argument_group("sampling (default: the model's sampling.json, else the SamplingConfig defaults)")
    smp.add_argument("--sampler", choices=SAMPLERS, help="sampler")
    smp.add_argument("--steps", type=integer(1, MAX_STEPS), help="sampling steps, 1..1000")
    smp.add_argument("--eta", type=real(0.0, 1.0), help="DDIM η in [0, 1] (0: deterministic)")
    smp.add_argument("--guidance", type=real(*GUIDANCE_RANGE), help="classifier-free guidance scale (1 = off)")
    smp.add_argument("--alpha", type=real(*ALPHA_RANGE), help="adapter strength α (0 = backbone only)")
    smp.add_argument("--env-guidance", type=real(*ENV_GUIDANCE_RANGE), help="environment guidance s_e (1 = off; continuous φ only)")
    smp.add_argument("--edit-t", type=integer(0, MAX_STEPS - 1), help="last timestep (0..999) at which φ off Earth's gravity follows Earth")
    smp.add_argument("--guidance-min-t", type=integer(0, MAX_STEPS - 1),
                     help="text guidance only at timesteps >= this (0..999; 0 = every step)")
    smp.add_argument("--foot-lock", type=real(0.0, 1.0), help="foot cleanup strength in [0, 1] (0 = off)")
    smp.add_argument("--flight-passes", type=integer(0, MAX_FLIGHT_PASSES),
                     help="flight guidance passes per step (0 = off): flights bent onto parabolas of the gravity")
    p.add_argument("--unbatched-cfg", action="store_true", help="run CFG as two forwards (MDM's way) instead of one")
    p.add_argument("--seed", type=SEED, default=0, help="noise seed (default 0)")
    p.add_argument("--batch", type=integer(1, MAX_MOTIONS), default=1, help=f"samples per caption (default 1; at most {MAX_MOTIONS} motions per run)")
    p.add_argument("--device", default="cpu", help="torch device (default cpu)")
    p.add_argument("--clip-weights", help="local CLIP ViT-B/32 weights file (models trained with clip)")
    p.add_argument("--out", type=Path, default=Path("samples"), help="output folder (default ./samples)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Sample; a run that fails leaves no output folder it created."""
    created = not args.out.exists()
    try:
        return _sample(args)
    except BaseException:
        if created:
            try:
                args.out.rmdir()
            except OSError:
                pass
        raise


def _sample(args: argparse.Namespace) -> int:
    import numpy as np

    from simdiff.errors import SimdiffError
    from simdiff.fsio import check_writable, output_set, save_npy, write_json
    from simdiff.inference.default import sampling_config
    from simdiff.inference.device import torch_device
    from simdiff.inference.generator import MotionGenerator
    from simdiff.motion.rigid import joints_from_features
    from simdiff.product.request import check_text

    args.text = [check_text(t) for t in args.text]
    if len(args.text) * args.batch > MAX_MOTIONS:
        raise SimdiffError(f"{len(args.text)} --text × --batch {args.batch} is {len(args.text) * args.batch} motions; "
                           f"the limit is {MAX_MOTIONS} per run")
    if args.env is not None:
        from simdiff.sim.env import Environment

        Environment(*args.env).validate(force=True)
    config = sampling_config(args.model).updated(**{f.name: getattr(args, f.name) for f in fields(SamplingConfig)})
    device = torch_device(args.device)
    from simdiff.text.base import check_weights_option

    check_weights_option(args.clip_weights)
    check_writable(args.out / "samples.json")
    gen = MotionGenerator.load(args.model, device, text_weights=args.clip_weights)
    texts = [t for t in args.text for _ in range(args.batch)]
    bar = None
    if not args.no_progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=config.steps * -(-len(texts) // CHUNK), desc=f"{config.sampler} sampling", unit="step",
                   leave=False, dynamic_ncols=True)

    def progress(steps):
        for t in steps:
            yield t
            if bar is not None:
                bar.update(1)

    index = []
    with output_set(args.out, last="samples.json") as stage:  # all files appear together, or none
        for c in range(0, len(texts), CHUNK):  # bounded memory: CHUNK motions at a time
            out = gen.generate(texts[c:c + CHUNK], args.length, config, env=args.env, env_index=args.env_index,
                               seed=chunk_seed(args.seed, c // CHUNK), batched_cfg=not args.unbatched_cfg,
                               progress=progress)
            for i, clip in enumerate(out.clips(), start=c):
                features = clip.cpu().numpy().astype(np.float32)
                save_npy(stage / f"sample_{i:03d}.npy", features)
                save_npy(stage / f"sample_{i:03d}_joints.npy", joints_from_features(features, config.foot_lock))
                index.append({"file": f"sample_{i:03d}.npy", "joints": f"sample_{i:03d}_joints.npy", "text": texts[i],
                              "frames": int(features.shape[0]), "fps": 20})
        if bar is not None:
            bar.close()
        meta = {"model": str(args.model), **config.to_dict(), "seed": args.seed, "env": args.env,
                "env_index": args.env_index, "samples": index}
        write_json(stage / "samples.json", meta, indent=2, allow_nan=False)
    print(f"wrote {len(index)} motion(s) to {args.out}")
    return 0


def chunk_seed(seed: int, chunk: int) -> int:
    """Noise seed of the ``chunk``-th group of :data:`CHUNK` motions: ``seed`` for the first, then seeds drawn from
    ``(seed, chunk)`` so that no two chunks of any run share noise."""
    if chunk == 0:
        return seed
    import numpy as np

    return int(np.random.SeedSequence([seed, chunk]).generate_state(1)[0])
