"""Every "done when" figure of issue 14 on one model folder: check.json + check.md.

Usage::

    nice -n 10 python benchmarks/model_check.py --model DIR --corpus CORPUS --evaluator EVAL_DIR \
        [--split test] [--n 256] [--seeds 0 1 2 3 4] [--jump-samples 32] [--speed-samples 16] \
        [--steps 50] [--length 120] [--workers 0] [--speed] [--quick] [--fresh] [--out reports/model_check/NAME]

Sections: the test-split protocol at Earth φ (sliding, skate ratio, R@3, FID and the GT floor,
one replication per seed), jump/hop prompts (flight ≥ 0.2 s with the pelvis ≥ 15 cm up), walk/run
speeds against the corpus's train clips, the physics response to g = −1.6 and ±10 N wind against
the simulator (models with a Sim Encoder), and ``--speed``: ``benchmarks/bench_generate.py``.
``--quick``: n = 16, one seed, 10 DDIM steps, 4 samples per prompt (a smoke run, not a claim).
``--also-evaluator DIR`` (repeatable): further evaluators score the same test-split motions (each generated
once); reported beside the first evaluator's figures, which the verdicts use.
Finished sections are kept in ``<out>/parts/`` and reused by a rerun with the same settings and the same model files
(weights' size and mtime, ``config.json``'s hash).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def parse(argv: list[str] | None = None) -> argparse.Namespace:
    from simdiff.product.request import ANCHORS  # torch-free

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--model", required=True, help="model folder (model.safetensors + config.json)")
    p.add_argument("--corpus", required=True, help="corpus folder, HumanML3D layout (+ manifest.json for speeds)")
    p.add_argument("--evaluator", required=True, help="our evaluator's folder (the verdicts use it)")
    p.add_argument("--also-evaluator", action="append", default=[], metavar="DIR",
                   help="a further evaluator that scores the same test-split motions (repeatable; reported, not judged)")
    p.add_argument("--split", default="test")
    p.add_argument("--n", type=int, default=256, help="test motions per replication (default 256)")
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4], help="one replication per seed")
    p.add_argument("--jump-samples", type=int, default=32, help="samples per jump prompt, split over the seeds")
    p.add_argument("--speed-samples", type=int, default=16, help="samples per walk/run prompt, split over the seeds")
    p.add_argument("--length", type=int, default=120, help="frames per prompt sample (20 fps; default 120)")
    p.add_argument("--steps", type=int, default=50, help="DDIM steps (default 50)")
    p.add_argument("--guidance", type=float, default=2.5)
    p.add_argument("--alpha", type=float, default=1.0, help="adapter strength of SimDiff models")
    p.add_argument("--foot-lock", type=float, default=0.0, help="foot-lock strength in [0, 1] (0: off)")
    p.add_argument("--env-guidance", type=float, default=1.0,
                   help="environment guidance s_e of SimDiff models (1: off; changes only motions off Earth)")
    p.add_argument("--env-guidance-fallback", type=float, default=None, metavar="S",
                   help="s_e for the prompt samples that float or glide at --env-guidance (re-sampled; default off)")
    p.add_argument("--anchor", default="adapters", choices=ANCHORS,
                   help="what the text guidance runs on (backbone: the adapters add only their answer to φ vs Earth)")
    p.add_argument("--anchor-alpha", type=float, default=0.0, metavar="A",
                   help="with --anchor backbone, reference or edit: the adapter strength of its text guidance (0: the "
                        "backbone alone)")
    p.add_argument("--anchor-t-max", type=int, default=None, metavar="T",
                   help="with --anchor backbone or reference: that anchor only at timesteps <= T (default every step)")
    p.add_argument("--eta", type=float, default=0.0, metavar="ETA",
                   help="DDIM eta in [0, 1] (0: deterministic, the default; 1: fresh noise at every step)")
    p.add_argument("--edit-t", type=int, default=None, metavar="T",
                   help="with --anchor edit: motions under another gravity follow their Earth motion down to "
                        "timestep T (default 800)")
    p.add_argument("--ballistic", type=float, default=0.0, metavar="S",
                   help="ballistic flight strength in [0, 1] (0: off): flights follow the parabola of the sample's "
                        "gravity")
    p.add_argument("--workers", type=int, default=0, help="simulator processes (0: all cores)")
    p.add_argument("--no-response", action="store_true", help="skip the physics-response section")
    p.add_argument("--speed", action="store_true", help="also run benchmarks/bench_generate.py (3 runs)")
    p.add_argument("--threads", type=int, default=0, help="torch threads (0: torch's default)")
    p.add_argument("--device", default="cpu")
    p.add_argument("--quick", action="store_true", help="smoke preset: n 16, one seed, 10 steps, 4 samples per prompt")
    p.add_argument("--fresh", action="store_true", help="measure every section again (ignore <out>/parts)")
    p.add_argument("--out", help="report folder (default reports/model_check/<model folder name>)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    return p.parse_args(argv)


def generation_speed(model: str, threads: int) -> dict:
    """Run ``benchmarks/bench_generate.py`` on ``model`` (3 runs, no import profile); its JSON."""
    with tempfile.TemporaryDirectory(prefix="model_check_speed_") as tmp:
        out = Path(tmp) / "bench.json"
        cmd = [sys.executable, str(ROOT / "benchmarks" / "bench_generate.py"), "--model", model, "--repeats", "3",
               "--no-importtime", "--json", str(out)] + (["--threads", str(threads)] if threads else [])
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0 or not out.is_file():
            last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
            return {"skipped": f"bench_generate.py failed (rc {proc.returncode}): {last}"}
        return json.loads(out.read_text())


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    from simdiff.errors import SimdiffError

    try:
        import torch

        from simdiff.eval.model_check import CheckConfig, ModelCheck, quick_preset
        from simdiff.eval.model_check.config import PromptOptions, ResponseOptions, SplitOptions

        if args.threads:
            torch.set_num_threads(args.threads)
        out = args.out or str(ROOT / "reports" / "model_check" / Path(args.model).resolve().name)
        config = CheckConfig(model=args.model, corpus=args.corpus, evaluator=args.evaluator, out=out, seeds=args.seeds,
                             steps=args.steps, guidance=args.guidance, alpha=args.alpha,
                             foot_lock=args.foot_lock, env_guidance=args.env_guidance, anchor=args.anchor,
                             env_guidance_fallback=args.env_guidance_fallback, anchor_alpha=args.anchor_alpha,
                             anchor_t_max=args.anchor_t_max, edit_t=args.edit_t, eta=args.eta, ballistic=args.ballistic,
                             more_evaluators=list(args.also_evaluator), device=args.device,
                             split=SplitOptions(split=args.split, n=args.n),
                             prompts=PromptOptions(jump_samples=args.jump_samples, speed_samples=args.speed_samples,
                                                   length=args.length),
                             response=ResponseOptions(enabled=not args.no_response, workers=args.workers))
        if args.quick:
            config = quick_preset(config)
        start = time.perf_counter()
        check = ModelCheck(config, progress=not args.quiet, fresh=args.fresh, command=[sys.argv[0], *(argv or sys.argv[1:])])
        speed = generation_speed(args.model, args.threads) if args.speed else None
        report = check.run(speed)
    except SimdiffError as exc:
        print(f"model_check: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("model_check: interrupted (finished sections are kept in <out>/parts)", file=sys.stderr)
        return 130
    for v in report["verdicts"]:
        mark = {True: "PASS", False: "FAIL", None: "n/a "}[v["passed"]]
        print(f"{mark}  {v['check']}: {v['value']} vs {v['threshold']}")
    print(f"wrote {Path(config.out) / 'check.json'} and check.md in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
