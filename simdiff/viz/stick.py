"""Stick-figure animations (GIF/MP4) and filmstrips (PNG) of (T, 22, 3) joint motions.

Matplotlib runs headless on its Agg canvas (no pyplot, no display). Animations build the
figure once, draw the static scene once, and per frame only restore that background and
redraw the moving artists (blitting), which keeps a 120-frame GIF at a few seconds.
"""

from __future__ import annotations

import textwrap
from dataclasses import replace
from pathlib import Path
from typing import Iterator, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from simdiff.fsio import atomic_path
from simdiff.motion.skeleton import FPS
from simdiff.viz._checks import (
    ANIMATION_SUFFIXES, IMAGE_SUFFIXES, as_captions, as_motions, output_path, positive_float, positive_int,
)
from simdiff.viz.camera import auto_height, choose_azim
from simdiff.viz.panel import DEFAULT_STYLE, StickPanel, Style, share_scale
from simdiff.viz.video import write_video

CAPTION_FONT: float = 9.0
"""Caption font size in points."""
LABEL_STRIP: float = 0.17
"""Height in inches kept free below each panel for its time label."""


def _wrap(caption: str, width_in: float, max_lines: int = 3) -> str:
    """Wrap ``caption`` to a panel ``width_in`` inches wide, at most ``max_lines`` lines."""
    chars = max(10, int(0.9 * width_in * 72 / (CAPTION_FONT * 0.6)))
    lines = textwrap.wrap(caption, chars)
    if len(lines) > max_lines:
        lines = lines[:max_lines]
        lines[-1] = lines[-1][: chars - 1].rstrip() + "…"
    return "\n".join(lines)


def _band_height(texts: Sequence[str]) -> float:
    """Height in inches reserved above a panel for the tallest wrapped caption."""
    n_lines = max((t.count("\n") + 1 for t in texts if t), default=0)
    return 0.08 + n_lines * CAPTION_FONT * 1.3 / 72 if n_lines else 0.0


class AnimationScene:
    """Side-by-side panels, one per motion, rendered frame by frame to RGB arrays.

    All panels share one azimuth, elevation and scale (metres per pixel, :func:`share_scale`),
    each centred on its own clip.

    Args:
        motions: list of (T_i, 22, 3) world joints (metres); shorter clips hold their last frame.
        captions: one title per motion.
        fps: frame rate (frames per second), used for the time labels.
        panel_size: (width, height) of one panel in inches; height None fits the clips' boxes.
        dpi: pixels per inch.
    """

    def __init__(self, motions: list[np.ndarray], captions: list[str], fps: float = FPS,
                 panel_size: tuple[float, float | None] = (3.2, None), dpi: int = 100, style: Style = DEFAULT_STYLE) -> None:
        n = len(motions)
        style = shared_view(motions, style)
        pw, ph = panel_size
        ph = auto_height(motions, pw, style.elev, style.azim) + LABEL_STRIP if ph is None else ph
        strip = min(LABEL_STRIP, 0.2 * ph)
        texts = [_wrap(c, pw) for c in captions]
        band = _band_height(texts)
        self.fig = Figure(figsize=(pw * n, ph + band), dpi=dpi, facecolor="white")
        self.canvas = FigureCanvasAgg(self.fig)
        self.fps = fps
        self.n_frames = max(m.shape[0] for m in motions)
        height = ph + band
        self.panels: list[StickPanel] = []
        self.clocks = []
        for i, (motion, text) in enumerate(zip(motions, texts)):
            ax = self.fig.add_axes((i / n, strip / height, 1.0 / n, (ph - strip) / height), projection="3d")
            self.panels.append(StickPanel(ax, motion, animated=True, style=style))
            if text:
                self.fig.text((i + 0.5) / n, 1.0 - 0.04 / height, text, ha="center", va="top", fontsize=CAPTION_FONT)
            self.clocks.append(self.fig.text((i + 0.03) / n, 0.03 / height, "", fontsize=7.5, color="#555555", animated=True))
        share_scale(self.panels)
        self._background = None

    def frame(self, t: int) -> np.ndarray:
        """(H, W, 3) uint8 image of global frame ``t``."""
        if self._background is None:
            self.canvas.draw()  # static artists only; animated ones are skipped
            self._background = self.canvas.copy_from_bbox(self.fig.bbox)
        self.canvas.restore_region(self._background)
        for panel, clock in zip(self.panels, self.clocks):
            panel.set_frame(t)
            for artist in panel.dynamic_artists():
                panel.ax.draw_artist(artist)
            i = panel.frame_index(t)
            clock.set_text(f"{i / self.fps:5.2f} s" + ("  (end)" if t > i else ""))
            self.fig.draw_artist(clock)
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()

    def frames(self) -> Iterator[np.ndarray]:
        """All frames, 0 .. max(T_i) - 1."""
        for t in range(self.n_frames):
            yield self.frame(t)


def animation_frames(motions: Sequence[np.ndarray] | np.ndarray, captions: Sequence[str] | None = None,
                     fps: float = FPS, panel_size: tuple[float, float | None] = (3.2, None), dpi: int = 100) -> Iterator[np.ndarray]:
    """Yield the (H, W, 3) uint8 frames of a side-by-side animation (for logging or custom writers)."""
    motions = as_motions(motions)
    scene = AnimationScene(motions, as_captions(captions, len(motions)), positive_float(fps, "fps"), panel_size, dpi)
    yield from scene.frames()


def render_animation(motions: Sequence[np.ndarray] | np.ndarray, path: str | Path,
                     captions: Sequence[str] | None = None, fps: float = FPS,
                     panel_size: tuple[float, float | None] = (3.2, None), dpi: int = 100) -> Path:
    """Render motions side by side to a GIF or MP4 (chosen by the suffix of ``path``).

    Args:
        motions: list of (T_i, 22, 3) joints in metres, Y-up; shorter clips hold their last frame.
        path: output file, ``.gif`` or ``.mp4``; missing parent folders are created.
        captions: one title per motion, or None.
        fps: playback rate in frames per second (HumanML3D: 20).
        panel_size: (width, height) of one panel in inches (height None: fit the clips); ``dpi`` pixels per inch.
    Returns:
        The written path. The video has ``max(T_i)`` frames.
    """
    motions = as_motions(motions)
    captions = as_captions(captions, len(motions))
    fps = positive_float(fps, "fps")
    path = output_path(path, ANIMATION_SUFFIXES)
    scene = AnimationScene(motions, captions, fps, panel_size, dpi)
    write_video(scene.frames(), path, fps)
    return path


def filmstrip_indices(n_total: int, n_frames: int) -> np.ndarray:
    """``n_frames`` evenly spaced frame indices in [0, n_total - 1], first and last included."""
    return np.round(np.linspace(0, n_total - 1, n_frames)).astype(int)


def filmstrip_figure(motions: list[np.ndarray], captions: list[str], n_frames: int = 8, fps: float = FPS,
                     cell_size: tuple[float, float | None] = (1.7, None), dpi: int = 100
                     ) -> tuple[Figure, list[list[StickPanel]]]:
    """The figure of :func:`render_filmstrip` (validated arguments) and its panels, one list per row."""
    cw, ch = cell_size
    style = shared_view(motions, DEFAULT_STYLE)
    shown = [[_around(m, int(t), n_frames) for t in filmstrip_indices(m.shape[0], n_frames)] for m in motions]
    ch = auto_height([w for row in shown for w, _ in row], cw, style.elev, style.azim) + LABEL_STRIP if ch is None else ch
    strip = min(LABEL_STRIP, 0.2 * ch)
    width = cw * n_frames
    texts = [_wrap(c, width, max_lines=2) for c in captions]
    band = _band_height(texts)
    row_h = ch + band
    height = row_h * len(motions)
    fig = Figure(figsize=(width, height), dpi=dpi, facecolor="white")
    FigureCanvasAgg(fig)
    rows: list[list[StickPanel]] = []
    for r, (motion, text) in enumerate(zip(motions, texts)):
        top = 1.0 - r * row_h / height
        if text:
            fig.text(0.5, top - 0.04 / height, text, ha="center", va="top", fontsize=CAPTION_FONT, weight="bold")
        bottom = top - row_h / height
        rows.append([])
        for c, (t, (window, at)) in enumerate(zip(filmstrip_indices(motion.shape[0], n_frames), shown[r])):
            ax = fig.add_axes((c / n_frames, bottom + strip / height, 1.0 / n_frames, (ch - strip) / height),
                              projection="3d")
            rows[-1].append(StickPanel(ax, window, style=style))
            rows[-1][-1].set_frame(at)
            fig.text((c + 0.5) / n_frames, bottom + 0.03 / height, f"{t / fps:.2f} s", ha="center", va="bottom",
                     fontsize=7.5, color="#555555")
        if r > 0:
            fig.add_artist(_rule(top))
    share_scale([p for row in rows for p in row])
    return fig, rows


LOCAL_VIEW_M: float = 8.0
"""Root travel (m) above which each filmstrip cell shows only its own stretch of the motion: drawn whole in each of
8 cells, a 30 m walk's body is 8 px tall; drawn by stretches, 37 px."""


def _around(motion: np.ndarray, t: int, n_frames: int) -> tuple[np.ndarray, int]:
    """What one filmstrip cell draws for frame ``t``: the whole motion and ``t``, or, for a motion travelling more than
    :data:`LOCAL_VIEW_M`, the frames between this cell's neighbours and ``t``'s index in them."""
    root = motion[:, 0, [0, 2]]
    if float(np.linalg.norm(root.max(0) - root.min(0))) <= LOCAL_VIEW_M or n_frames < 2:
        return motion, t
    half = int(np.ceil((motion.shape[0] - 1) / (n_frames - 1) / 2))
    lo = max(0, t - half)
    return motion[lo: t + half + 1], t - lo


def render_filmstrip(motions: Sequence[np.ndarray] | np.ndarray, path: str | Path,
                     captions: Sequence[str] | None = None, n_frames: int = 8, fps: float = FPS,
                     cell_size: tuple[float, float | None] = (1.7, None), dpi: int = 100) -> Path:
    """Save a grid image: one row per motion, ``n_frames`` evenly spaced frames per row.

    Every cell uses the same fixed camera angles and scale (metres per pixel); each row is
    centred on its clip (each cell on its own stretch for a motion travelling more than :data:`LOCAL_VIEW_M`),
    titled by its caption, and each cell labelled by its time in seconds.

    Args:
        motions: list of (T_i, 22, 3) joints in metres, Y-up.
        path: output image (``.png``; also ``.jpg``, ``.pdf``, ``.svg``).
        captions: one title per motion, or None.
        n_frames: frames per row.
        fps: frame rate used for the time labels.
        cell_size: (width, height) of one cell in inches (height None: fit the clips); ``dpi`` pixels per inch.
    """
    motions = as_motions(motions)
    captions = as_captions(captions, len(motions))
    n_frames = positive_int(n_frames, "n_frames")
    fps = positive_float(fps, "fps")
    path = output_path(path, IMAGE_SUFFIXES)
    fig, _ = filmstrip_figure(motions, captions, n_frames, fps, cell_size, dpi)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, facecolor="white")
    return path


def shared_view(motions: Sequence[np.ndarray], style: Style) -> Style:
    """``style`` with one azimuth for every panel (the first motion's, :func:`~simdiff.viz.camera.choose_azim`), so
    side-by-side motions are seen from the same side: per-motion choices mirrored an Earth jump and its Moon twin."""
    if style.azim is not None:
        return style
    return replace(style, azim=choose_azim(np.asarray(motions[0])))


def _rule(y: float):
    """A thin horizontal separator line across the figure at figure fraction ``y``."""
    from matplotlib.lines import Line2D

    return Line2D([0.01, 0.99], [y, y], color="#dddddd", lw=0.8)
