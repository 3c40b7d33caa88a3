"""``simdiff sample``: sample motions from a trained model folder (backbone or SimDiff)."""

from __future__ import annotations

import argparse
from dataclasses import fields
from pathlib import Path

from simdiff.diffusion.config import SAMPLERS, SamplingConfig


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "sample",
        help="sample motions from a trained model (text, length, gravity/wind, sampler, guidance)",
        description="Sample motions with DDPM or DDIM and classifier-free guidance from a model folder "
                    "(model.safetensors + config.json). Writes features (T, 263) and joints (T, 22, 3) as .npy.",
    )
    p.add_argument("--model", type=Path, required=True, help="model folder, e.g. runs/backbone/model")
    p.add_argument("--text", action="append", required=True, help="caption (repeat for several)")
    p.add_argument("--length", type=int, default=120, help="frames at 20 fps, 1..196 (default 120 = 6 s)")
    p.add_argument("--env", type=float, nargs=3, metavar=("G_Z", "W_X", "W_Y"),
                   help="φ for SimDiff models: gravity m/s² and wind N (default -9.81 0 0)")
    p.add_argument("--env-index", type=int, help="environment category for categorical SimDiff models")
    smp = p.add_argument_group("sampling (default: the model's sampling.json, else the SamplingConfig defaults)")
    smp.add_argument("--sampler", choices=SAMPLERS, help="sampler")
    smp.add_argument("--steps", type=int, help="sampling steps, 1..1000")
    smp.add_argument("--eta", type=float, help="DDIM η in [0, 1] (0: deterministic)")
    smp.add_argument("--guidance", type=float, help="classifier-free guidance scale (1 = off)")
    smp.add_argument("--alpha", type=float, help="adapter strength α (0 = backbone only)")
    smp.add_argument("--env-guidance", type=float, help="environment guidance s_e (1 = off; continuous φ only)")
    smp.add_argument("--edit-t", type=int, help="last timestep (0..999) at which φ off Earth's gravity follows Earth")
    smp.add_argument("--foot-lock", type=float, help="foot cleanup strength in [0, 1] (0 = off)")
    p.add_argument("--unbatched-cfg", action="store_true", help="run CFG as two forwards (MDM's way) instead of one")
    p.add_argument("--seed", type=int, default=0, help="noise seed (default 0)")
    p.add_argument("--batch", type=int, default=1, help="samples per caption (default 1)")
    p.add_argument("--device", default="cpu", help="torch device (default cpu)")
    p.add_argument("--clip-weights", help="local CLIP ViT-B/32 weights file (models trained with clip)")
    p.add_argument("--out", type=Path, default=Path("samples"), help="output folder (default ./samples)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np
    import torch

    from simdiff.errors import SimdiffError
    from simdiff.fsio import check_writable, ensure_dir, save_npy, write_json
    from simdiff.inference.default import sampling_config
    from simdiff.inference.generator import MAX_FRAMES, MotionGenerator

    from simdiff.product.request import check_text

    args.text = [check_text(t) for t in args.text]
    if not 1 <= args.length <= MAX_FRAMES:
        raise SimdiffError(f"--length must be 1..{MAX_FRAMES} frames (9.8 s at 20 fps), got {args.length}")
    if args.batch < 1:
        raise SimdiffError("--batch must be at least 1")
    config = sampling_config(args.model).updated(**{f.name: getattr(args, f.name) for f in fields(SamplingConfig)})
    try:
        device = torch.device(args.device)
    except RuntimeError:
        raise SimdiffError(f"unknown device {args.device!r}") from None
    ensure_dir(args.out)
    check_writable(args.out / "samples.json")
    gen = MotionGenerator.load(args.model, device, text_weights=args.clip_weights)
    texts = [t for t in args.text for _ in range(args.batch)]
    def progress(steps):
        from tqdm.auto import tqdm

        return tqdm(steps, desc=f"{config.sampler} sampling", unit="step", leave=False, dynamic_ncols=True)

    out = gen.generate(texts, args.length, config, env=args.env, env_index=args.env_index, seed=args.seed,
                       batched_cfg=not args.unbatched_cfg, progress=None if args.no_progress else progress)
    try:
        from simdiff.motion.features import features_to_joints
    except ImportError:  # pragma: no cover - the motion package ships with simdiff
        features_to_joints = None
    index = []
    for i, clip in enumerate(out.clips()):
        features = clip.cpu().numpy().astype(np.float32)
        save_npy(args.out / f"sample_{i:03d}.npy", features)
        entry = {"file": f"sample_{i:03d}.npy", "text": texts[i], "frames": int(features.shape[0]), "fps": 20}
        if features_to_joints is not None:
            save_npy(args.out / f"sample_{i:03d}_joints.npy", features_to_joints(features))
            entry["joints"] = f"sample_{i:03d}_joints.npy"
        index.append(entry)
    meta = {"model": str(args.model), **config.to_dict(), "seed": args.seed, "env": args.env,
            "env_index": args.env_index, "samples": index}
    write_json(args.out / "samples.json", meta, indent=2)
    print(f"wrote {len(index)} motion(s) to {args.out}")
    return 0
