"""``simdiff serve [FILE...]``: a local web viewer with a 3D skeleton player, a prompt box and
gravity / wind / α sliders that regenerate the motion."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simdiff.cli.options import integer
from simdiff.diffusion.config import MAX_STEPS
from simdiff.errors import Terminated

def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "serve",
        help="local web viewer: 3D skeleton player, prompt box, gravity/wind/α sliders, open .npy/.bvh",
        description="Serve a local web page that plays motions in 3D (orbit, zoom, timeline), generates them "
                    "from a prompt under gravity and wind with the default (or --model) model, and opens "
                    "motion files. Listens on 127.0.0.1 only unless --host says otherwise.",
    )
    p.add_argument("files", nargs="*", type=Path, metavar="FILE",
                   help="motions to open: .npy joints (T, 22, 3) or features (T, 263), .bvh, .amc, DeepMimic .txt/.json")
    p.add_argument("--port", type=integer(0, 65535), default=8765, help="TCP port (default 8765; 0 picks a free one)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this machine only; 0.0.0.0 exposes it to the network)")
    p.add_argument("--model", type=Path, help="model folder (default: $SIMDIFF_MODEL, else the shipped model)")
    p.add_argument("--steps", type=integer(1, MAX_STEPS), help="DDIM sampling steps (default 50; fewer is faster, rougher)")
    p.add_argument("--queue", type=integer(1, 64), default=4, metavar="N",
                   help="generation requests that may wait behind the running one; more get 429 (default 4)")
    p.add_argument("--device", default="cpu", help="torch device for generation (default cpu)")
    p.add_argument("--no-browser", action="store_true", help="do not open a browser tab")
    p.set_defaults(func=run)


def build_server(args: argparse.Namespace):  # -> simdiff.serve.ViewerServer (imports kept lazy)
    """Check the arguments, read the listed files and bind the server (does not serve yet).

    Raises:
        SimdiffError: bad port or device, unreadable file, address in use.
    """
    from tqdm.auto import tqdm

    from simdiff.inference.device import torch_device

    from simdiff.errors import SimdiffError
    from simdiff.serve import MotionService, ViewerServer, read_listed
    from simdiff.diffusion.config import MAX_STEPS

    if not 0 <= args.port <= 65535:
        raise SimdiffError(f"--port must be 0..65535, got {args.port}")
    if args.queue < 0:
        raise SimdiffError(f"--queue must be ≥ 0, got {args.queue}")
    if args.steps is not None and not 1 <= args.steps <= MAX_STEPS:
        raise SimdiffError(f"--steps must be 1..{MAX_STEPS}, got {args.steps}")
    torch_device(args.device)

    def files_progress(items):
        return tqdm(items, desc="reading files", unit="file", leave=False, disable=len(items) < 2)

    def sampling_progress(steps):
        return tqdm(steps, desc="generating", unit="step", leave=False, dynamic_ncols=True)

    listed = read_listed(args.files, files_progress)
    service = MotionService(args.model, device=args.device, files=listed, progress=sampling_progress,
                            steps=args.steps, max_queue=args.queue)
    return ViewerServer(service, args.host, args.port, verbose=True)


def run(args: argparse.Namespace) -> int:
    import webbrowser

    server = build_server(args)
    status = server.service.model_status()
    print(f"simdiff serve: {server.url}  (Ctrl+C to stop)", flush=True)
    print(f"  model: {status['path']}" + (f" — {status['error']}" if status["error"] else f" ({status['kind']}, loads on first use)"),
          flush=True)
    if server.any_host or server.server_address[0] not in ("127.0.0.1", "::1", "localhost"):
        print(f"  warning: listening on {args.host}: anyone who can reach this machine can use the viewer", file=sys.stderr)
    if not args.no_browser:
        webbrowser.open(server.url)
    try:
        server.serve_forever()
    except KeyboardInterrupt as exc:  # the usual way to stop it: one line, and the status a shell expects
        print("simdiff serve: stopped", file=sys.stderr)
        return 143 if isinstance(exc, Terminated) else 130
    finally:
        server.server_close()
    return 0
