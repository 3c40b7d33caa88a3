"""``simdiff generate TEXT``: text (+ gravity, wind) → motion files with the shipped default model."""

from __future__ import annotations

import argparse
import sys
from contextlib import nullcontext
from pathlib import Path
from typing import TYPE_CHECKING

from simdiff.product.request import ANCHORS

if TYPE_CHECKING:
    from simdiff.product.finisher import Finisher
    from simdiff.product.request import GenerationRequest

EPILOG = """\
outputs (in --out, default ./out/<prompt>/), per sample K = 0, 1, ...:
  sampleK_joints.npy     (T, 22, 3) joint positions, metres, Y-up, 20 fps
  sampleK_features.npy   (T, 263) un-normalised HumanML3D features, one row per joint frame
  sampleK.bvh            BVH animation (metres, Y-up, 20 fps; Blender: scale 1)
  sampleK.gif            stick-figure animation (.mp4 with --format npy,bvh,mp4)
  generation.json        prompt, environment, seed, sampler, steps, guidance, alpha, foot lock, env guidance,
                         model, timings
with --simulate, also (the final sample re-tracked in the simulator under the same φ):
  sampleK_simulated_joints.npy  (T', 22, 3) the simulator's motion (T' = T unless it fell or a flight
                                lasted longer/shorter under φ); sampleK_simulated.bvh with bvh
  sampleK_tracking.json  tracking result: success/status/fall frame, joint error, d_L2, residual
                         forces, physics metrics of the generated and the simulated motion, seconds
with --compare, files are named <component><value>_sampleK.* and one video
compare_sampleK.gif shows the environments side by side (same prompt, same noise).

examples:
  simdiff generate "a person jumps forward" --gravity -3.7 --wind 2 0
  simdiff generate "a person walks in a circle" --length 8 --num-samples 3 --no-video
  simdiff generate "a person jumps forward" --compare gravity=-9.81,-3.7,-1.6
  simdiff generate "a person jumps forward" --gravity -3.7 --simulate
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "generate",
        help="generate a motion from text under gravity and wind (default model)",
        description="Generate a motion from a text prompt under explicit gravity and wind with the\n"
                    "shipped default model (or --model / $SIMDIFF_MODEL) and write it as .npy joints\n"
                    "and features, a BVH and a stick-figure GIF. Runs on the CPU; --simulate also re-tracks\n"
                    "the result in the MuJoCo simulator under the same φ and writes the simulated motion.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("text", metavar="TEXT", help='what the person does, e.g. "a person jumps forward"')
    env = p.add_argument_group("environment φ")
    env.add_argument("--gravity", type=float, metavar="G",
                     help="vertical gravity in m/s², negative (default -9.81 Earth; Mars -3.7, Moon -1.6)")
    env.add_argument("--wind", type=float, nargs=2, metavar=("X", "Y"),
                     help="horizontal wind force in newtons along +X and +Z (the character's left and "
                          "forward at frame 0) (default 0 0)")
    env.add_argument("--compare", metavar="SPEC",
                     help="render the same prompt and seed under several environments side by side: "
                          "gravity=-9.81,-3.7,-1.6 or wind_x=... or wind_y=... (replaces that component)")
    env.add_argument("--simulate", action="store_true",
                     help="simulated finish: re-track each final sample in the simulator under φ and write the "
                          "simulated motion and its tracking result beside it")
    env.add_argument("--force", action="store_true",
                     help="allow environments outside the trained range (gravity -20..-1 m/s², |wind| <= 10 N)")
    smp = p.add_argument_group("sampling")
    length = smp.add_mutually_exclusive_group()
    length.add_argument("--length", type=float, metavar="SECONDS", help="motion length in seconds, up to 9.8 (default 6)")
    length.add_argument("--frames", type=int, metavar="N", help="motion length in frames at 20 fps, 1..196 (default 120)")
    smp.add_argument("--seed", type=int, default=0, metavar="S", help="noise seed; sample K uses seed+K (default 0)")
    smp.add_argument("--num-samples", type=int, default=1, metavar="K", help="samples to generate (default 1)")
    smp.add_argument("--sampler", choices=["ddim", "ddpm"], help="diffusion sampler (default ddim)")
    smp.add_argument("--steps", type=int, metavar="N", help="diffusion steps (default 50 for ddim, 1000 for ddpm)")
    smp.add_argument("--eta", type=float, metavar="E",
                     help="DDIM's noise scale in [0, 1]: 0 deterministic, 1 fresh noise at every step (default 0, or "
                          "the model's sampling.json)")
    smp.add_argument("--guidance", type=float, metavar="W", help="classifier-free guidance scale, 1 = off (default 2.5)")
    smp.add_argument("--alpha", type=float, metavar="A",
                     help="strength of the environment adapters, 0 = ignore φ (default 1, or the model's sampling.json)")
    smp.add_argument("--foot-lock", type=float, metavar="S",
                     help="foot cleanup, strength 0..1: move the root so the feet the motion marks planted do not "
                          "slide, lift swinging feet that drag along the floor 2 cm clear of it, and lower a motion "
                          "that never comes within 0.10 m of the floor onto it "
                          "(0 = off; default 0, or the model's sampling.json)")
    smp.add_argument("--env-guidance", type=float, metavar="S",
                     help="push the adapters' answer to φ (against Earth without wind) S times as far, 1 = off; "
                          "motions under Earth without wind are unchanged (default 1, or the model's sampling.json)")
    smp.add_argument("--env-guidance-fallback", type=float, metavar="S",
                     help="environment guidance for the samples that come out floating (never within 0.10 m of the "
                          "floor) or gliding (travelling while no foot lifts 5 cm) at --env-guidance: they are "
                          "sampled again with the same seed at S (default off, or the model's sampling.json)")
    smp.add_argument("--anchor", choices=ANCHORS,
                     help="what the text guidance runs on: the network with its adapters (adapters), or the backbone "
                          "alone, the adapters adding only their answer to φ against Earth without wind (backbone), "
                          "or the network under Earth without wind at --anchor-alpha, the adapters anchor's whole "
                          "answer to φ added (reference), or, under another gravity, that network until --edit-t, "
                          "then the adapters under φ (edit); default adapters, or the model's sampling.json")
    smp.add_argument("--anchor-alpha", type=float, metavar="A",
                     help="with --anchor backbone, reference or edit: run its text guidance with the adapters at strength "
                          "A, so motions under Earth without wind are those of --alpha A while the answer to φ is "
                          "--alpha's (default 0, or the model's sampling.json)")
    smp.add_argument("--anchor-t-max", type=int, metavar="T",
                     help="with --anchor backbone or reference: use it only at the denoising steps whose timestep is "
                          "at most T (0-999), the adapters anchor at the earlier ones (default every step, or the "
                          "model's sampling.json)")
    smp.add_argument("--edit-t", type=int, metavar="T",
                     help="with --anchor edit: a motion under another gravity follows its Earth motion (same "
                          "seed) down to timestep T (0-999), then continues under its gravity and wind (default 800, or the "
                          "model's sampling.json)")
    smp.add_argument("--ballistic", type=float, metavar="S",
                     help="ballistic flight strength in [0, 1]: while no foot is on the ground the body's height "
                          "follows the parabola of the chosen gravity (1), as generated (0); default 0, or the "
                          "model's sampling.json")
    out = p.add_argument_group("output")
    out.add_argument("--out", type=Path, metavar="DIR",
                     help="output folder, files in it are replaced (default ./out/<prompt>, or <prompt>-2, -3, ... "
                          "when that one is not empty)")
    out.add_argument("--format", metavar="LIST",
                     help="comma-separated outputs among npy, bvh, gif, mp4 (default npy,bvh,gif)")
    out.add_argument("--no-video", action="store_true", help="skip the GIF/MP4 (fastest)")
    out.add_argument("-q", "--quiet", action="store_true",
                     help="no progress bars or notes (warnings still show); print only the file paths")
    run_ = p.add_argument_group("model and compute")
    run_.add_argument("--model", type=Path, metavar="DIR",
                      help="model folder with model.safetensors + config.json (default $SIMDIFF_MODEL, else the "
                           "shipped model)")
    run_.add_argument("--device", default="cpu", help="torch device, e.g. cpu or cuda (default cpu)")
    run_.add_argument("--threads", type=int, metavar="N",
                      help="CPU threads for torch (default: the idle cores, from the load average)")
    p.set_defaults(func=run)


def _note(args: argparse.Namespace, message: str) -> None:
    """A one-line note on stderr (hidden by --quiet)."""
    if not args.quiet:
        print(f"simdiff: {message}", file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    import time

    from simdiff.errors import SimdiffError
    from simdiff.product.request import build_request

    start = time.perf_counter()
    request = build_request(  # every user value is checked before torch is imported
        args.text, gravity=args.gravity, wind=args.wind, length_s=args.length, frames=args.frames, seed=args.seed,
        num_samples=args.num_samples, sampler=args.sampler or "ddim", steps=args.steps,
        guidance=2.5 if args.guidance is None else args.guidance, alpha=1.0 if args.alpha is None else args.alpha,
        foot_lock=0.0 if args.foot_lock is None else args.foot_lock,
        env_guidance=1.0 if args.env_guidance is None else args.env_guidance, anchor=args.anchor or "adapters",
        env_guidance_fallback=args.env_guidance_fallback,
        anchor_alpha=0.0 if args.anchor_alpha is None else args.anchor_alpha,
        anchor_t_max=args.anchor_t_max, edit_t=args.edit_t, eta=0.0 if args.eta is None else args.eta,
        ballistic=0.0 if args.ballistic is None else args.ballistic,
        compare=args.compare, formats=args.format,
        no_video=args.no_video, force=args.force,
    )
    if args.threads is not None and args.threads < 1:
        raise SimdiffError(f"--threads must be at least 1, got {args.threads}")
    finisher = None
    if args.simulate:  # the simulator loads in its own process while this one loads torch and samples
        from simdiff.product.finisher import start_finisher

        finisher = start_finisher(request.num_samples * len(request.envs))
    with finisher if finisher is not None else nullcontext():  # an error or Ctrl-C stops the worker at once
        return _generate(args, request, start, finisher)


def _generate(args: argparse.Namespace, request: GenerationRequest, start: float, finisher: Finisher | None) -> int:
    """Load the model, sample (the finish in ``finisher``'s process when given), write and report."""
    import time

    from simdiff.errors import SimdiffError
    from simdiff.product.outputs import fresh_dir, prepare_out_dir, slug
    from simdiff.product.request import with_model_defaults
    from simdiff.sim.env import GRAVITY_RANGE, MAX_WIND
    from simdiff.model.default import check_model_dir, sampling_defaults  # imports torch (simdiff.model)

    folder = check_model_dir(args.model)
    stored = sampling_defaults(args.model)
    from simdiff.model.extrapolate import read_recipe
    from simdiff.model.provenance import read_provenance

    read_provenance(folder)  # a malformed provenance.json fails now, not after sampling
    read_recipe(folder)  # likewise extrapolation.json
    given = {name for name in ("sampler", "steps", "guidance", "alpha", "foot_lock", "env_guidance",
                               "env_guidance_fallback", "anchor", "anchor_alpha", "anchor_t_max", "edit_t",
                               "ballistic", "eta")
             if getattr(args, name) is not None}
    request = with_model_defaults(request, stored, given)
    alpha_source = "--alpha" if "alpha" in given else ("sampling.json" if "alpha" in stored else "default")
    for env in request.envs:
        try:
            env.validate()
        except SimdiffError:
            lo, hi = GRAVITY_RANGE
            print(f"simdiff: warning: {env.as_tuple()} is outside the trained range (gravity {lo:g}..{hi:g} m/s², "
                  f"|wind| <= {MAX_WIND:g} N); the motion is an extrapolation", file=sys.stderr)
            break
    out_dir = prepare_out_dir(args.out if args.out is not None else fresh_dir(Path("out") / slug(request.text)))
    from simdiff.fsio import check_writable

    check_writable(out_dir / "generation.json")  # a read-only folder fails now, not after sampling

    import torch

    from simdiff.model.default import load_default
    from simdiff.product.pipeline import Timer, describe_env, run_generation

    try:
        device = torch.device(args.device)
    except (RuntimeError, ValueError):
        raise SimdiffError(f"unknown --device {args.device!r}; use cpu or cuda") from None
    from simdiff.product.threads import default_threads

    torch.set_num_threads(args.threads if args.threads is not None else default_threads(torch.get_num_threads()))
    timer = Timer()
    _note(args, f"loading model {folder}")
    with timer.stage("load_model"):
        generator = load_default(args.model, device)
    if not generator.is_simdiff:
        ignored = [name for name, value in (("--gravity", args.gravity), ("--wind", args.wind),
                                            ("--alpha", args.alpha), ("--compare", args.compare)) if value is not None]
        if ignored:
            print(f"simdiff: warning: {folder} is a backbone-only model (no environment input); "
                  f"{', '.join(ignored)} ignored", file=sys.stderr)
        request = request.with_envs(request.envs[:1])
    elif generator.config.sim.mode != "continuous":
        raise SimdiffError(f"{folder} has categorical environments; use `simdiff sample --env-index` with it")
    meta, paths = run_generation(generator, request, out_dir, folder, timer, args.quiet, alpha_source,
                                 simulate=args.simulate, force=args.force, finisher=finisher)
    from simdiff.motion.metrics import FLOOR_CLEARANCE, GLIDE_LIFT

    for rec in meta["samples"]:
        if not rec["touches_floor"]:
            print(f"simdiff: warning: sample {rec['index']} never comes within {FLOOR_CLEARANCE:.2f} m of the floor "
                  f"(lowest joint {rec['lowest_m']:.2f} m): it floats; under a φ far from Earth or a strong "
                  "--env-guidance the model extrapolates", file=sys.stderr)
        elif rec.get("glides"):
            print(f"simdiff: warning: sample {rec['index']} glides: it travels while no foot lifts {GLIDE_LIFT:.2f} m "
                  "(a frozen pose carried along); under a φ far from Earth or a strong --env-guidance the model "
                  "extrapolates", file=sys.stderr)
    for rec in meta["samples"] if args.simulate else []:
        sim = rec["simulated"]
        name = rec["files"].get("tracking", f"sample {rec['index']}").removesuffix("_tracking.json")
        if not sim["success"]:
            print(f"simdiff: warning: the simulated finish of {name} {sim['status']} at frame "
                  f"{sim['fall_frame']}; its simulated motion ends there ({sim['n_out']} of {sim['n_frames']} frames)",
                  file=sys.stderr)
        slide = (sim.get("physics_simulated") or {}).get("sliding")
        second = ("" if (sim.get("attempts") or 1) < 2 else
                  "; second try under the slip guard " + ("kept" if sim.get("fallback") else "not kept"))
        _note(args, f"{name} simulated: {sim['status']} ({sim['n_out']} frames, joint error {sim['err_mm']:.0f} mm"
                    f"{'' if slide is None else f', sliding {slide:.2f} mm/frame'}, {sim['wall_s']:.2f} s{second})")
    for path in paths:
        print(path)
    n = len(meta["samples"])
    where = describe_env(request.envs[0]) if generator.is_simdiff and request.compare is None else (
        f"{len(request.envs)} environments" if generator.is_simdiff else describe_env(None))
    _note(args, f"{n} motion{'s' if n > 1 else ''} of {request.frames} frames ({request.seconds:g} s), {where}, "
                f"in {time.perf_counter() - start:.1f} s")
    return 0
