"""Write RGB frames to GIF (Pillow, one shared palette) or MP4 (imageio-ffmpeg, H.264), atomically.

GIF: a per-frame adaptive palette (imageio's GIF plugin) costs about 15 ms per 320×185
frame; stick figures and body renders use few flat colours plus anti-aliasing shades, so one
palette computed once from a mosaic of frames looks the same and maps every frame about 10×
faster (no dithering: flat colours stay flat). Both writers encode to a temporary file beside
the target and rename it on success (:mod:`simdiff.fsio`), so a failure leaves no partial file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Iterable

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import atomic_path

PALETTE_COLOURS: int = 96
"""Colours in the shared GIF palette (GIF allows 256)."""
MAX_GIF_FPS: float = 50.0
"""Fastest GIF: 2-centisecond frames (browsers slow 1-centisecond GIF frames down)."""
MIN_GIF_FPS: float = 0.01
MAX_GIF_BYTES: int = 1 << 30
"""Most RGB frame data a GIF is built from (one shared palette needs every frame before the first is written)."""
PALETTE_SAMPLES: int = 12
"""Frames (evenly spaced) the GIF palette is computed from."""


def _even(frame: np.ndarray) -> np.ndarray:
    """Pad an (H, W, 3) frame with white to even height and width (needed by yuv420p)."""
    h, w = frame.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return frame
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), constant_values=255)


def write_gif(frames: Iterable[np.ndarray], path: str | Path, fps: float, colours: int = PALETTE_COLOURS) -> int:
    """Write (H, W, 3) uint8 RGB frames as a looping GIF with one shared palette.

    Args:
        frames: equally sized (H, W, 3) uint8 images.
        path: output ``.gif`` file (its folder is created).
        fps: playback rate in frames per second; GIF delays are whole centiseconds (20 fps is exact).
        colours: palette size, 2..256.
    Returns:
        The number of frames written.
    """
    from PIL import Image

    if not 2 <= colours <= 256:
        raise SimdiffError(f"GIF palette size must be 2..256, got {colours}")
    if not MIN_GIF_FPS <= fps <= MAX_GIF_FPS:  # GIF delays are whole centiseconds, at most 655.35 s
        raise SimdiffError(f"{str(path)!r}: a GIF plays at {MIN_GIF_FPS:g}..{MAX_GIF_FPS:g} fps, got {fps:g}; "
                           "write an .mp4 instead")
    stack, size = [], 0
    for f in frames:
        stack.append(np.ascontiguousarray(f, dtype=np.uint8))
        size += stack[-1].nbytes
        if size > MAX_GIF_BYTES:
            raise SimdiffError(f"{str(path)!r}: a GIF of this many frames needs more than {MAX_GIF_BYTES >> 20} MiB; "
                               "write an .mp4 instead")
    if not stack:
        raise SimdiffError(f"no frames to write to {str(path)!r}")
    picks = np.unique(np.linspace(0, len(stack) - 1, min(PALETTE_SAMPLES, len(stack))).round().astype(int))
    mosaic = Image.fromarray(np.concatenate([stack[i] for i in picks], axis=0))
    palette = mosaic.quantize(colors=colours, method=Image.Quantize.MEDIANCUT)
    images = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in stack]
    with atomic_path(path) as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=1000.0 / fps, loop=0)
        check_video(tmp, len(images), path, fps)
    return len(images)


def write_mp4(frames: Iterable[np.ndarray], path: str | Path, fps: float) -> int:
    """Write (H, W, 3) uint8 frames as an H.264 MP4 at ``fps``; returns the number of frames."""
    import imageio_ffmpeg

    count = 0
    with atomic_path(path) as tmp:
        writer = None
        try:
            for frame in frames:
                frame = _even(np.ascontiguousarray(frame, dtype=np.uint8))
                if writer is None:
                    h, w = frame.shape[:2]
                    writer = imageio_ffmpeg.write_frames(
                        str(tmp), (w, h), fps=fps, codec="libx264", pix_fmt_out="yuv420p",
                        macro_block_size=1, quality=7, ffmpeg_log_level="quiet",  # failures: check_video
                    )
                    writer.send(None)  # start ffmpeg
                writer.send(frame)
                count += 1
        finally:
            if writer is not None:
                writer.close()
        if count == 0:
            raise SimdiffError(f"no frames to write to {str(path)!r}")
        check_video(tmp, count, path, fps)
    return count


def check_video(written: Path, frames: int, target: str | Path, fps: float) -> None:
    """Read back the video just written to ``written`` and check it holds ``frames`` frames at ``fps`` (an encoder
    that hit a full disk can exit cleanly with a truncated file); else one :class:`SimdiffError` naming ``target``.
    GIF merges repeated frames into one longer frame, so there the total duration is what is checked."""
    try:
        if written.suffix.lower() == ".gif":
            from PIL import Image, ImageSequence

            with Image.open(written) as image:
                total_ms = sum(float(f.info.get("duration", 0)) for f in ImageSequence.Iterator(image))
            found = int(round(total_ms * fps / 1000.0))
        else:
            import imageio_ffmpeg

            found = int(imageio_ffmpeg.count_frames_and_secs(str(written))[0])
    except (OSError, RuntimeError, ValueError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise SimdiffError(f"cannot write {str(target)!r}: the written video does not open ({first[:120]})") from None
    if abs(found - frames) > max(1, frames // 100):  # GIF stores whole milliseconds per frame
        raise SimdiffError(f"cannot write {str(target)!r}: the written video holds {found} of {frames} frames "
                           "(disk full?)")


def write_video(frames: Iterable[np.ndarray], path: str | Path, fps: float) -> int:
    """Dispatch on the suffix of ``path`` (``.gif`` or ``.mp4``); returns the number of frames."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".gif":
        return write_gif(frames, path, fps)
    if suffix == ".mp4":
        return write_mp4(frames, path, fps)
    raise SimdiffError(f"unsupported video suffix {suffix!r} in {str(path)!r}; use .gif or .mp4")
