"""``simdiff sample``: sample motions from a trained model folder (backbone or SimDiff)."""

from __future__ import annotations

import argparse
from pathlib import Path


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
    p.add_argument("--alpha", type=float, default=1.0, help="adapter strength α (0 = backbone only; default 1)")
    p.add_argument("--sampler", choices=["ddim", "ddpm"], default="ddim", help="sampler (default ddim)")
    p.add_argument("--steps", type=int, help="sampling steps (default: 50 for ddim, 1000 for ddpm)")
    p.add_argument("--eta", type=float, default=0.0, help="DDIM η (default 0, deterministic)")
    p.add_argument("--guidance", type=float, default=2.5, help="classifier-free guidance scale (default 2.5; 1 = off)")
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
    from simdiff.model.generator import MAX_FRAMES, MotionGenerator

    from simdiff.product.request import check_text

    args.text = [check_text(t) for t in args.text]
    if not 1 <= args.length <= MAX_FRAMES:
        raise SimdiffError(f"--length must be 1..{MAX_FRAMES} frames (9.8 s at 20 fps), got {args.length}")
    if args.batch < 1:
        raise SimdiffError("--batch must be at least 1")
    if args.steps is not None and args.steps < 1:
        raise SimdiffError("--steps must be positive")
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

        return tqdm(steps, desc=f"{args.sampler} sampling", unit="step", leave=False, dynamic_ncols=True)

    out = gen.generate(texts, args.length, env=args.env, env_index=args.env_index, alpha=args.alpha,
                       sampler=args.sampler, steps=args.steps, eta=args.eta, guidance=args.guidance, seed=args.seed,
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
    meta = {"model": str(args.model), "sampler": args.sampler, "steps": args.steps, "guidance": args.guidance,
            "seed": args.seed, "alpha": args.alpha, "env": args.env, "env_index": args.env_index, "samples": index}
    write_json(args.out / "samples.json", meta, indent=2)
    print(f"wrote {len(index)} motion(s) to {args.out}")
    return 0
