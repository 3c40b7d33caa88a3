"""Write RGB frames to GIF (imageio/Pillow) or MP4 (imageio-ffmpeg, H.264)."""

from __future__ import annotations

from pathlib import Path
from typing import Iterable

import numpy as np

from simdiff.errors import SimdiffError


def _even(frame: np.ndarray) -> np.ndarray:
    """Pad an (H, W, 3) frame with white to even height and width (needed by yuv420p)."""
    h, w = frame.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return frame
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), constant_values=255)


def write_gif(frames: Iterable[np.ndarray], path: Path, fps: float) -> int:
    """Write (H, W, 3) uint8 frames as a looping GIF; returns the number of frames.

    GIF delays are whole centiseconds, so 20 fps (5 cs) is exact; other rates are rounded.
    """
    import imageio.v3 as iio

    stack = np.stack(list(frames))
    iio.imwrite(path, stack, extension=".gif", duration=1000.0 / fps, loop=0)
    return len(stack)


def write_mp4(frames: Iterable[np.ndarray], path: Path, fps: float) -> int:
    """Write (H, W, 3) uint8 frames as an H.264 MP4 at ``fps``; returns the number of frames."""
    import imageio_ffmpeg

    writer = None
    count = 0
    try:
        for frame in frames:
            frame = _even(np.ascontiguousarray(frame, dtype=np.uint8))
            if writer is None:
                h, w = frame.shape[:2]
                writer = imageio_ffmpeg.write_frames(
                    str(path), (w, h), fps=fps, codec="libx264", pix_fmt_out="yuv420p",
                    macro_block_size=1, quality=7, ffmpeg_log_level="error",
                )
                writer.send(None)  # start ffmpeg
            writer.send(frame)
            count += 1
    finally:
        if writer is not None:
            writer.close()
    if count == 0:
        raise SimdiffError(f"no frames to write to {str(path)!r}")
    return count


def write_video(frames: Iterable[np.ndarray], path: Path, fps: float) -> int:
    """Dispatch on the suffix of ``path`` (``.gif`` or ``.mp4``)."""
    suffix = path.suffix.lower()
    if suffix == ".gif":
        return write_gif(frames, path, fps)
    if suffix == ".mp4":
        return write_mp4(frames, path, fps)
    raise SimdiffError(f"unsupported video suffix {suffix!r} in {str(path)!r}; use .gif or .mp4")
