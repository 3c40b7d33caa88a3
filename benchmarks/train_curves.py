"""Learning curves per CPU-hour of one backbone/training design (issue 14: choose the CPU design by measurement).

Usage::

    python benchmarks/train_curves.py --corpus CORPUS --design small_geo_crop --minutes 60 --points 6 \
        [--evaluator EVAL_DIR] [--out reports/training] [--seed 10] [--heldout 32] [--sample-steps 20]

Appends/replaces the design's curve in ``<out>/curves.json`` and redraws ``<out>/curves.png``.
Designs: see ``simdiff.train.curves.DESIGNS``. CPU time counts the training steps only (all
threads of this process); evaluation between points is not counted. Without ``--evaluator``
R@3 is not measured (``null``). Held-out data: the corpus's ``val`` split (else ``test``).
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import torch


def main(argv: list[str] | None = None) -> int:
    from simdiff.data.humanml3d import HumanML3D
    from simdiff.errors import SimdiffError
    from simdiff.fsio import write_json
    from simdiff.motion.skeleton import MIN_FRAMES
    from simdiff.train.curves import DESIGNS, design_config, design_factor, held_out, plot_curves, rescore, run_curve
    from simdiff.train.trainer import Trainer

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--corpus", type=Path, required=True)
    p.add_argument("--design", choices=sorted(DESIGNS), required=True)
    p.add_argument("--minutes", type=float, default=10.0, help="training CPU-minutes")
    p.add_argument("--points", type=int, default=5, help="evaluations along the way")
    p.add_argument("--evaluator", type=Path, help="our trained evaluator folder (for R@3)")
    p.add_argument("--text-encoder", default="minilm", help="minilm, or hash (smoke tests: no text meaning)")
    p.add_argument("--out", type=Path, default=Path("reports/training"))
    p.add_argument("--run-dir", type=Path,
                   help="trainer folder, checkpointed at every point; calling again with more --minutes continues it "
                        "(default: a temporary folder, not kept)")
    p.add_argument("--rescore", action="store_true",
                   help="do not train: recompute the sample metrics of --run-dir's saved points (R@3 with --evaluator)")
    p.add_argument("--seed", type=int, default=10)
    p.add_argument("--heldout", type=int, default=32, help="held-out items evaluated")
    p.add_argument("--sample-steps", type=int, default=20, help="DDIM steps of the samples")
    p.add_argument("--lowfps-corpus", type=Path,
                   help="low-frame-rate designs: the 10 fps copy of --corpus (built there, resumably, when missing)")
    p.add_argument("--threads", type=int, default=0, help="torch threads (0: leave as is)")
    args = p.parse_args(argv)
    try:
        if args.threads:
            torch.set_num_threads(args.threads)
        if args.text_encoder == "hash":
            from simdiff.train.testing import HashTextEncoder

            encoder = HashTextEncoder()
        else:
            from simdiff.text.base import load_text_encoder

            encoder = load_text_encoder(args.text_encoder)
        factor = design_factor(args.design)
        corpus = args.corpus
        if factor > 1:
            from simdiff.train.lowfps import build_lowfps_corpus

            if args.lowfps_corpus is None:
                raise SimdiffError(f"design {args.design} trains at 1/{factor} of 20 fps: give --lowfps-corpus DIR")
            build_lowfps_corpus(args.corpus, args.lowfps_corpus, factor)
            corpus = args.lowfps_corpus
        split = "val" if (corpus / "val.txt").is_file() and (corpus / "val.txt").read_text().strip() else "test"
        min_frames = MIN_FRAMES // factor
        train = HumanML3D(corpus, "train", seed=args.seed, min_frames=min_frames)
        held_ds = HumanML3D(corpus, split, normalizer=train.normalizer, seed=args.seed, min_frames=min_frames)
        evaluator = None
        if args.evaluator is not None:
            from simdiff.eval.evaluator import OurEvaluator

            evaluator = OurEvaluator.load(args.evaluator, text_encoder=encoder)
        held = held_out(held_ds, min(args.heldout, len(held_ds)), args.seed, evaluator, factor)
        config = design_config(args.design, args.text_encoder, encoder.dim, args.seed)
        import tempfile

        path = args.out / "curves.json"
        curves = json.loads(path.read_text()) if path.is_file() else {}
        start = time.time()
        if args.rescore:
            if args.run_dir is None or args.design not in curves:
                raise SimdiffError("--rescore needs --run-dir and the design's entry in <out>/curves.json")
            points = rescore(args.run_dir, held, evaluator, factor)
        else:
            run_dir = args.run_dir or Path(tempfile.mkdtemp(prefix=f"curve_{args.design}_"))
            trainer = Trainer(run_dir, config, train, text_encoder=encoder, resume=args.run_dir is not None)
            points = run_curve(trainer, held, args.minutes, args.points, evaluator=evaluator,
                               sample_steps=args.sample_steps, factor=factor, save=args.run_dir is not None)
        if args.rescore:
            curves[args.design].update(points=points, ground_truth=held.gt,
                                       evaluator=str(args.evaluator) if args.evaluator else None)
        else:
            curves[args.design] = {"points": points, "ground_truth": held.gt, "corpus": str(corpus), "fps": 20 // factor, "heldout_split": split,
                                   "heldout_items": len(held.batch["lengths"]), "train_clips": len(train),
                                   "text_encoder": args.text_encoder, "evaluator": str(args.evaluator) if args.evaluator else None,
                                   "threads": torch.get_num_threads(), "machine": platform.processor() or platform.machine(),
                                   "minutes": max(args.minutes, points[-1]["cpu_s"] / 60.0 if points else 0.0),
                                   "wall_s": round(time.time() - start, 1), "seed": args.seed,
                                   "run_dir": str(args.run_dir) if args.run_dir else None}
        write_json(path, curves)
        plot_curves(curves, args.out / "curves.png")
        print(f"wrote {path} and {args.out / 'curves.png'}")
    except SimdiffError as exc:
        print(f"train_curves: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
