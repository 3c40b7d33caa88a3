"""``simdiff render``: stick-figure (or, with ``--body``, skinned body) GIF/MP4 animations and PNG filmstrips."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.options import FPS_OPTION, integer
from simdiff.errors import SimdiffError

MAX_STRIP_FRAMES: int = 64
"""Most frames per filmstrip row."""
MAX_SIZE: int = 4096
"""Largest panel width or height in pixels (``--size``)."""
MAX_RENDER_FRAMES: int = 12000
"""Longest motion rendered as an animation (10 min at 20 fps); checked before any frame is drawn."""
MAX_PANELS: int = 16
"""Most motions rendered side by side."""
MAX_GIF_PANEL_FRAMES: int = 4000
"""Most frames × panels in a GIF (about 0.9 GB of frames held for its shared palette); MP4 streams, so it has none."""


def _load(path: Path):
    """(T, 22, 3) joints from ``path`` via :func:`simdiff.motion.io.load_joints`, or a raw ``.npy``."""
    try:
        from simdiff.motion.io import check_regular_file, load_joints
    except ImportError:
        load_joints = None
    if load_joints is not None:
        check_regular_file(path)
        return load_joints(path)
    if not path.is_file():
        raise SimdiffError(f"motion file not found: {str(path)!r}")
    if path.suffix.lower() != ".npy":
        raise SimdiffError(f"cannot read {str(path)!r}: only .npy (T, 22, 3) joint files are supported here")
    import numpy as np

    try:
        return np.load(path, allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise SimdiffError(f"cannot read {str(path)!r}: {exc}") from None


def _run(args: argparse.Namespace) -> int:
    from simdiff.motion.skeleton import FPS
    from simdiff.viz import render_animation, render_filmstrip

    files = [Path(f) for f in args.files]
    motions = [_load(f) for f in files]
    for f, m in zip(files, motions):
        if getattr(m, "ndim", 0) != 3 or tuple(m.shape[1:]) != (22, 3):
            raise SimdiffError(f"{str(f)!r} has shape {tuple(getattr(m, 'shape', ()))}, expected (T, 22, 3) joints")
    if len(motions) > MAX_PANELS:
        raise SimdiffError(f"{len(motions)} motions given; render at most {MAX_PANELS} side by side")
    longest = max(int(m.shape[0]) for m in motions)
    if longest > MAX_RENDER_FRAMES:
        raise SimdiffError(f"{files[[int(m.shape[0]) for m in motions].index(longest)]} has {longest} frames; "
                           f"render at most {MAX_RENDER_FRAMES} (cut it with numpy first)")
    if Path(args.out).suffix.lower() == ".gif" and longest * len(motions) > MAX_GIF_PANEL_FRAMES:
        raise SimdiffError(f"{longest} frames × {len(motions)} panels is more than a GIF holds here "
                           f"({MAX_GIF_PANEL_FRAMES}); write an .mp4 instead")
    captions = args.caption if args.caption else [f.stem for f in files]
    out = Path(args.out)
    fps = args.fps if args.fps is not None else FPS
    if args.body:
        return _run_body(args, motions, captions, out, fps)
    from simdiff.cli.feedback import slow_notice

    with slow_notice(f"rendering {out}"):
        if args.filmstrip or out.suffix.lower() == ".png":
            render_filmstrip(motions, out, captions=captions, n_frames=args.frames, fps=fps)
        else:
            render_animation(motions, out, captions=captions, fps=fps)
    print(out)
    return 0


def _run_body(args: argparse.Namespace, motions: list, captions: list[str], out: Path, fps: float) -> int:
    """``--body``: the project's skinned body (the glTF export's mesh) posed by the joints, MuJoCo offscreen OpenGL."""
    from simdiff.viz.body import render_body

    if args.filmstrip and out.suffix.lower() != ".png":
        raise SimdiffError(f"--body --filmstrip writes a .png, got {str(out)!r}")
    size = tuple(args.size) if args.size is not None else None
    render_body(motions, out, captions=captions, fps=fps, size=size, n_frames=args.frames)
    print(out)
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``simdiff render``."""
    parser = subparsers.add_parser(
        "render",
        help="render joint motions as a stick-figure (or --body skinned body) GIF/MP4 or a PNG filmstrip",
        description="Render one or more (T, 22, 3) joint motions side by side. The output suffix picks the "
        "format: .gif or .mp4 animation, .png filmstrip (also with --filmstrip).",
    )
    parser.add_argument("files", nargs="+", metavar="FILE", help="joint motion files (T, 22, 3)")
    parser.add_argument("--out", required=True, metavar="PATH", help="output .gif, .mp4 or .png")
    parser.add_argument("--caption", action="extend", nargs="+", metavar="TEXT",
                        help="one caption per FILE (default: file names)")
    parser.add_argument("--filmstrip", action="store_true", help="save a filmstrip image instead of an animation")
    parser.add_argument("--frames", type=integer(1, MAX_STRIP_FRAMES), default=8, metavar="N", 
                        help=f"frames per filmstrip row, 1..{MAX_STRIP_FRAMES} (default 8)")
    parser.add_argument("--fps", type=FPS_OPTION, default=None, help="playback frames per second (default 20)")
    parser.add_argument("--body", action="store_true",
                        help="render the skinned body of the glTF export, posed by the joints, with shadows "
                        "(MuJoCo offscreen OpenGL: EGL or OSMesa) instead of stick figures")
    parser.add_argument("--size", type=integer(16, MAX_SIZE), nargs=2, default=None, metavar=("W", "H"),
                        help="--body: pixels per panel (default 640 480; filmstrip cells 320 360)")
    parser.set_defaults(func=_run)
