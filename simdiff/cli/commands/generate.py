"""``simdiff generate TEXT``: text (+ gravity, wind) → motion files with the shipped default model."""

from __future__ import annotations

import argparse
import sys
from contextlib import nullcontext
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING

from simdiff.cli.options import SEED, integer, real
from simdiff.diffusion.config import (ALPHA_RANGE, ENV_GUIDANCE_RANGE, GUIDANCE_RANGE, MAX_FLIGHT_PASSES, MAX_STEPS,
                                      SAMPLER_STEPS, SAMPLERS, SamplingConfig)
from simdiff.inference.default import DEFAULT_MODEL_DIR, SAMPLING_NAME, sampling_config
from simdiff.motion.skeleton import FPS, MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.product.request import MAX_SAMPLES
from simdiff.sim.env import MAX_FORCED_WIND, MAX_GRAVITY, MIN_FORCED_GRAVITY

if TYPE_CHECKING:
    from simdiff.inference.coverage import PromptCoverage
    from simdiff.inference.generator import MotionGenerator
    from simdiff.product.finisher import Finisher
    from simdiff.product.pipeline import Timer
    from simdiff.product.request import GenerationRequest

EPILOG = """\
outputs (in --out, default ./out/<prompt>/), per sample K = 0, 1, ...:
  sampleK_joints.npy     (T, 22, 3) joint positions, metres, Y-up, 20 fps
  sampleK_features.npy   (T, 263) un-normalised HumanML3D features, one row per joint frame
  sampleK.bvh            BVH animation (metres, Y-up, 20 fps; Blender: scale 1)
  sampleK.gif            stick-figure animation (.mp4 with --format npy,bvh,mp4)
  generation.json        prompt, environment, seed, sampler, steps, guidance, alpha, foot lock, env guidance,
                         model, the prompt's best match among the training captions, timings
with --simulate, also (the final sample re-tracked in the simulator under the same φ):
  sampleK_simulated_joints.npy  (T', 22, 3) the simulator's motion (T' = T unless it fell or a flight
                                lasted longer/shorter under φ); sampleK_simulated.bvh with bvh
  sampleK_tracking.json  tracking result: success/status/fall frame, joint error, d_L2, residual
                         forces, physics metrics of the generated and the simulated motion, seconds
with --compare, files are named <component><value>_sampleK.* and one video
compare_sampleK.gif shows the environments side by side (same prompt, same noise).

examples:
  simdiff generate "a person jumps forward" --gravity -3.7 --wind 2 0
  simdiff generate "a person walks in a circle" --length 8 --num-samples 3 --format npy,bvh
  simdiff generate "a person jumps forward" --compare gravity=-9.81,-3.7,-1.6
  simdiff generate "a person jumps forward" --gravity -3.7 --simulate
  simdiff generate "a person walks forward" --keyframes poses.npy
  simdiff generate --timeline day.json

--keyframes: frame 0 starts where the keyframes put the root and faces where their hips and shoulders face (at the
origin facing +Z when not given); every entry the skeleton can reach is met within 2 cm, joints given alone too
(inverse kinematics on the motion's fixed bones); a warning says when one ends further away.

a prompt (or timeline segment) far from every caption the model trained on gets a warning naming the nearest ones:
the model has probably not learned that motion (the model folder's captions.safetensors; `simdiff train coverage`).
"""


KEYFRAME_TOLERANCE: float = 0.02
"""m: a keyframe entry further than this from the written motion gets a warning."""
SINK_TOLERANCE: float = 0.05
"""m: a keyframed motion whose lowest joint goes further than this under y = 0 gets a warning (keyframe poses 1.3×
the model's size put the feet 14 cm under the floor between the keys)."""


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
    p.add_argument("text", metavar="TEXT", nargs="?", help='what the person does, e.g. "a person jumps forward" '
                                                           "(or --timeline)")
    env = p.add_argument_group("environment φ")
    env.add_argument("--gravity", type=real(MIN_FORCED_GRAVITY, MAX_GRAVITY), metavar="G",
                     help="vertical gravity in m/s², negative (default -9.81 Earth; Mars -3.7, Moon -1.6)")
    env.add_argument("--wind", type=real(-MAX_FORCED_WIND, MAX_FORCED_WIND), nargs=2, metavar=("X", "Y"),
                     help="horizontal wind force in newtons along +X and +Z (the character's left and "
                          "forward at frame 0) (default 0 0)")
    env.add_argument("--compare", metavar="SPEC",
                     help="render the same prompt and seed under several environments side by side: "
                          "gravity=-9.81,-3.7,-1.6 or wind_x=... or wind_y=... (replaces that component)")
    env.add_argument("--simulate", action="store_true",
                     help="simulated finish: re-track each final sample in the simulator under φ and write the "
                          "simulated motion and its tracking result beside it")
    env.add_argument("--force", action="store_true",
                     help="allow environments outside the trained range (gravity -20..-1 m/s², |wind| <= 10 N), up to "
                          f"gravity {MIN_FORCED_GRAVITY:g} m/s² and wind ±{MAX_FORCED_WIND:g} N")
    smp = p.add_argument_group("sampling (defaults: the model's sampling.json; shown: the shipped model's)")
    cfg = shipped_sampling()
    smp.add_argument("--length", type=real(MIN_GENERATE_FRAMES / FPS, MAX_FRAMES / FPS), metavar="SECONDS", help="motion length in seconds, up to 9.8 (default 6)")
    smp.add_argument("--keyframes", type=Path, metavar="FILE.npy",
                     help="(T, 22, 3) joints to meet, metres, Y-up, 20 fps, NaN for free entries: whole poses (in-between, "
                          "continuation, pinned poses) or the root's x/z alone (a path); the motion has T frames")
    smp.add_argument("--timeline", type=Path, metavar="FILE.json",
                     help='several prompts in a row as one motion of any length: a JSON list of {"text": ..., '
                          '"seconds": ..., "gravity"?: G, "wind"?: [X, Y]} (instead of TEXT, --length, --gravity, --wind)')
    smp.add_argument("--seed", type=SEED, default=0, metavar="S", help="noise seed; sample K uses seed+K (default 0)")
    smp.add_argument("--num-samples", type=integer(1, MAX_SAMPLES), default=1, metavar="K", help="samples to generate (default 1)")
    smp.add_argument("--sampler", choices=SAMPLERS, help=f"diffusion sampler (default {cfg.sampler})")
    smp.add_argument("--steps", type=integer(1, MAX_STEPS), metavar="N",
                     help=f"diffusion steps, 1..1000 (default {cfg.steps}; with a --sampler switched to another: "
                          + ", ".join(f"{k} {v}" for k, v in SAMPLER_STEPS.items() if k != cfg.sampler) + ")")
    smp.add_argument("--eta", type=real(0.0, 1.0), metavar="E",
                     help=f"DDIM's noise scale in [0, 1]: 0 deterministic, 1 fresh noise at every step (default "
                          f"{cfg.eta:g})")
    smp.add_argument("--guidance", type=real(*GUIDANCE_RANGE), metavar="W",
                     help=f"classifier-free guidance scale on the text, 1 = off (default {cfg.guidance:g})")
    smp.add_argument("--guidance-min-t", type=integer(0, MAX_STEPS - 1), metavar="T",
                     help=f"guide by the text only at denoising timesteps >= T, one network pass per step below it "
                          f"(0 = every step; default {cfg.guidance_min_t}; 0 with a --sampler switched to another)")
    smp.add_argument("--alpha", type=real(*ALPHA_RANGE), metavar="A",
                     help=f"strength of the environment adapters, 0 = ignore φ (default {cfg.alpha:g})")
    smp.add_argument("--foot-lock", type=real(0.0, 1.0), metavar="S",
                     help="foot cleanup, strength 0..1: hold the feet the motion marks planted in place by leg IK (the "
                          "root keeps its path), lift swinging feet that drag along the floor 4 cm clear of it, and lower a motion "
                          f"that never comes within 0.10 m of the floor onto it (0 = off; default {cfg.foot_lock:g})")
    smp.add_argument("--env-guidance", type=real(*ENV_GUIDANCE_RANGE), metavar="S",
                     help="push the adapters' answer to φ (against Earth without wind) S times as far, 1 = off "
                          f"(default {cfg.env_guidance:g})")
    smp.add_argument("--edit-t", type=integer(0, MAX_STEPS - 1), metavar="T",
                     help="under another gravity than Earth's, the motion follows its Earth motion (same seed) down "
                          f"to denoising timestep T (0-999), then continues under φ (default {cfg.edit_t})")
    smp.add_argument("--flight-passes", type=integer(0, MAX_FLIGHT_PASSES), metavar="N",
                     help="flight guidance: N passes per denoising step that bend every flight onto a parabola of the "
                          f"requested gravity, 0 = off (default {cfg.flight_passes})")
    out = p.add_argument_group("output")
    out.add_argument("--out", type=Path, metavar="DIR",
                     help="output folder, files in it are replaced (default ./out/<prompt>, or <prompt>-2, -3, ... "
                          "when that one is not empty)")
    out.add_argument("--format", metavar="LIST",
                     help="comma-separated outputs among npy, bvh, gif, mp4 (default npy,bvh,gif; npy,bvh is "
                          "fastest)")
    out.add_argument("-q", "--quiet", action="store_true",
                     help="no progress bars or notes (warnings still show); print only the file paths")
    run_ = p.add_argument_group("model and compute")
    run_.add_argument("--model", type=Path, metavar="DIR",
                      help="model folder with model.safetensors + config.json (default $SIMDIFF_MODEL, else the "
                           "shipped model)")
    run_.add_argument("--device", default="cpu", help="torch device, e.g. cpu or cuda (default cpu)")
    p.set_defaults(func=run)


def _note(args: argparse.Namespace, message: str) -> None:
    """A one-line note on stderr (hidden by --quiet)."""
    if not args.quiet:
        print(f"simdiff: {message}", file=sys.stderr)


def _check_prompts(args: argparse.Namespace, generator: MotionGenerator, request: GenerationRequest, folder: Path,
                   timer: Timer) -> list[PromptCoverage] | None:
    """Warn (one line each) about the prompts far from every caption the model trained on; a note when the
    model folder has no caption table. Returns :func:`simdiff.product.pipeline.prompt_coverage`'s answer."""
    from simdiff.inference.coverage import COVERAGE_NAME
    from simdiff.product.pipeline import prompt_coverage

    with timer.stage("check_prompt"):
        coverage = prompt_coverage(generator, request, folder)
    if coverage is None:
        _note(args, f"{folder} has no {COVERAGE_NAME}: the prompt is not checked against its training captions "
                    "(`simdiff train coverage CORPUS --model DIR` writes it)")
    for checked in coverage or []:
        if checked.far:
            print(f"simdiff: warning: {checked.warning()}", file=sys.stderr)
    return coverage


def shipped_sampling() -> SamplingConfig:
    """The shipped model's sampling configuration (one small JSON file; no torch)."""
    path = DEFAULT_MODEL_DIR / SAMPLING_NAME
    return SamplingConfig.read(path) if path.is_file() else SamplingConfig()


def given_sampling(args: argparse.Namespace) -> dict[str, object]:
    """The sampling options the user gave (None for the others)."""
    return {f.name: getattr(args, f.name) for f in fields(SamplingConfig)}


def run(args: argparse.Namespace) -> int:
    import time

    from simdiff.product.request import build_request

    start = time.perf_counter()
    sampling = sampling_config(args.model).updated(**given_sampling(args))
    request = build_request(  # every user value is checked before torch is imported
        args.text, gravity=args.gravity, wind=args.wind, length_s=args.length, seed=args.seed,
        num_samples=args.num_samples, sampling=sampling, compare=args.compare, formats=args.format, force=args.force,
        keyframes=args.keyframes, timeline=args.timeline,
    )
    if args.simulate and request.timeline is not None:
        from simdiff.errors import SimdiffError

        raise SimdiffError("--simulate re-tracks a motion under one φ, and a timeline has one per segment; leave "
                           "--simulate out")
    finisher = None
    if args.simulate:  # the simulator loads in its own process while this one loads torch and samples
        from simdiff.product.finisher import start_finisher

        finisher = start_finisher(request.num_samples * len(request.envs))
    with finisher if finisher is not None else nullcontext():  # an error or Ctrl-C stops the worker at once
        return _generate(args, request, start, finisher)


def _generate(args: argparse.Namespace, request: GenerationRequest, start: float, finisher: Finisher | None) -> int:
    """Load the model, sample (the finish in ``finisher``'s process when given), write and report."""

    from simdiff.errors import SimdiffError
    from simdiff.product.outputs import fresh_dir, prepare_out_dir, slug
    from simdiff.sim.env import GRAVITY_RANGE, MAX_WIND
    from simdiff.inference.default import check_model_dir
    from simdiff.model.extrapolate import read_recipe
    from simdiff.model.provenance import read_provenance

    folder = check_model_dir(args.model)
    read_provenance(folder)  # a malformed provenance.json fails now, not after sampling
    read_recipe(folder)  # likewise extrapolation.json
    for env in request.envs:
        try:
            env.validate()
        except SimdiffError:
            lo, hi = GRAVITY_RANGE
            print(f"simdiff: warning: {env.as_tuple()} is outside the trained range (gravity {lo:g}..{hi:g} m/s², "
                  f"|wind| <= {MAX_WIND:g} N); the motion is an extrapolation", file=sys.stderr)
            break
    out_dir = args.out if args.out is not None else fresh_dir(Path("out") / slug(request.text))
    created = not out_dir.exists()
    out_dir = prepare_out_dir(out_dir)
    try:
        return _generate_into(args, request, start, finisher, folder, out_dir)
    except BaseException:
        if created:  # a failed run leaves no empty folder behind
            try:
                out_dir.rmdir()
            except OSError:
                pass
        raise


def _generate_into(args: argparse.Namespace, request: GenerationRequest, start: float, finisher: Finisher | None,
                   folder: Path, out_dir: Path) -> int:
    """:func:`_generate` once the output folder exists."""
    import time

    from simdiff.errors import SimdiffError
    from simdiff.fsio import check_writable

    check_writable(out_dir / "generation.json")  # a read-only folder fails now, not after sampling

    from simdiff.inference.default import load_default
    from simdiff.inference.device import torch_device
    from simdiff.product.pipeline import Timer, describe_env, run_generation

    device = torch_device(args.device)
    timer = Timer()
    _note(args, f"loading model {folder}")
    with timer.stage("load_model"):
        generator = load_default(args.model, device)
    from simdiff.text.cache import CachedTextEncoder

    generator.text_encoder = CachedTextEncoder(generator.text_encoder, device)  # the prompt check's encoding is reused
    if not generator.is_simdiff:
        ignored = [name for name, value in (("--gravity", args.gravity), ("--wind", args.wind),
                                            ("--alpha", args.alpha), ("--compare", args.compare)) if value is not None]
        if ignored:
            print(f"simdiff: warning: {folder} is a backbone-only model (no environment input); "
                  f"{', '.join(ignored)} ignored", file=sys.stderr)
        request = request.with_envs(request.envs[:1])
    elif generator.config.sim.mode != "continuous":
        raise SimdiffError(f"{folder} has categorical environments; use `simdiff sample --env-index` with it")
    coverage = _check_prompts(args, generator, request, folder, timer)
    meta, paths = run_generation(generator, request, out_dir, folder, timer, args.quiet,
                                 simulate=args.simulate, force=args.force, finisher=finisher, coverage=coverage)
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
    keyframes = meta.get("keyframes")
    for rec in meta["samples"] if keyframes else []:  # generated motions are put on the floor; keyed ones may sink
        if rec["lowest_m"] < -SINK_TOLERANCE:
            print(f"simdiff: warning: sample {rec['index']} goes {-100 * rec['lowest_m']:.0f} cm under the floor "
                  "(keyframe poses on a skeleton larger than the model's do that between the keys: give them at "
                  "the model's size)", file=sys.stderr)
    if keyframes and max(keyframes["max_error_m"]) > KEYFRAME_TOLERANCE:
        print(f"simdiff: warning: a keyframe entry is {100 * max(keyframes['max_error_m']):.1f} cm from the motion; "
              "an entry out of the skeleton's reach, or contradicting another, is neared, not met", file=sys.stderr)
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
    if request.timeline is not None:
        where = f"{len(request.timeline)} timeline segments"
    _note(args, f"{n} motion{'s' if n > 1 else ''} of {request.frames} frames ({request.seconds:g} s), {where}, "
                f"in {time.perf_counter() - start:.1f} s")
    return 0
