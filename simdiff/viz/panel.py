"""One stick-figure view of one motion on a matplotlib 3D axes, updated in place.

World coordinates are metres, Y-up (floor at y=0). Matplotlib's 3D axes are Z-up, so the
panel plots the proper rotation ``(x, y, z) -> (x, -z, y)``; handedness is preserved, so a
figure is never mirrored.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.artist import Artist
from mpl_toolkits.mplot3d import Axes3D
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from simdiff.motion.skeleton import KINEMATIC_CHAIN, LEFT_CHAIN, RIGHT_CHAIN
from simdiff.viz.camera import choose_azim, clip_bounds, content_points, fill_scale, fit_view, screen_points, to_plot

HEAD: int = 15
"""Joint index drawn with a round head marker."""


@dataclass(frozen=True)
class Style:
    """Colours (matplotlib colour strings) and line widths (points) of a panel."""

    left: str = "#1f6fd1"
    right: str = "#d62728"
    centre: str = "#303030"
    trace: str = "#ff8c00"
    trace_planned: str = "#9a9a9a"
    floor: str = "#eeeeee"
    grid: str = "#b4b4b4"
    bone_width: float = 2.6
    head_size: float = 7.0
    elev: float = 20.0
    azim: float | None = None
    """Plot-space azimuth in degrees; None picks one per clip (:func:`choose_azim`)."""


DEFAULT_STYLE = Style()


def _grid_segments(lo: np.ndarray, hi: np.ndarray, z: float = 0.0) -> np.ndarray:
    """(S, 2, 3) world-aligned floor grid lines inside the box, at most ~12 per side."""
    span = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    step = next((s for s in (0.25, 0.5, 1.0, 2.0, 5.0) if span / s <= 12), 10.0)
    segs = []
    for x in np.arange(np.ceil(lo[0] / step), np.floor(hi[0] / step) + 1) * step:
        segs.append([[x, lo[1], z], [x, hi[1], z]])
    for y in np.arange(np.ceil(lo[1] / step), np.floor(hi[1] / step) + 1) * step:
        segs.append([[lo[0], y, z], [hi[0], y, z]])
    return np.asarray(segs, dtype=float).reshape(-1, 2, 3)


def _chain_colour(chain: tuple[int, ...], style: Style) -> str:
    limb = set(chain[1:])
    if limb & set(LEFT_CHAIN):
        return style.left
    if limb & set(RIGHT_CHAIN):
        return style.right
    return style.centre


class StickPanel:
    """Draws one motion on ``ax`` with a camera fixed for the whole clip.

    The panel's content (every joint of every frame and the floor) is centred in ``rect``, the
    axes' rectangle (figure fraction), at ``scale`` display pixels per metre: ``fill_scale``, the
    one at which the content fills ``rect``, unless :meth:`set_scale` or :func:`share_scale` set
    another. Static artists: floor plane, grid, the whole root path (dashed). Dynamic artists
    (``animated=True`` keeps them out of full redraws, for blitting): bones, head, the root path
    travelled so far.
    """

    def __init__(self, ax: Axes3D, motion: np.ndarray, *, animated: bool = False, style: Style = DEFAULT_STYLE) -> None:
        self.ax = ax
        self.style = style
        self.plot = to_plot(motion)  # (T, 22, 3)
        self.n_frames = int(motion.shape[0])
        lo, hi = clip_bounds(motion)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(lo[2], hi[2])
        azim = choose_azim(motion) if style.azim is None else style.azim
        ax.view_init(elev=style.elev, azim=azim)
        ax.set_proj_type("ortho")
        self.rect = ax.get_position(original=True).frozen()  # figure fraction
        self._box = (lo, hi, content_points(motion, lo, hi))
        self.fill_scale = fill_scale(ax, *self._box)  # display pixels per metre
        self.scale = self.fill_scale
        fit_view(ax, *self._box, self.scale)
        ax.patch.set_visible(False)  # panels may overlap after centring
        ax.set_axis_off()
        ax.computed_zorder = False
        ax.set_navigate(False)

        floor = [[lo[0], lo[1], 0.0], [hi[0], lo[1], 0.0], [hi[0], hi[1], 0.0], [lo[0], hi[1], 0.0]]
        ax.add_collection3d(Poly3DCollection([floor], facecolor=style.floor, edgecolor="none", zorder=0))
        ax.add_collection3d(Line3DCollection(_grid_segments(lo, hi), colors=style.grid, linewidths=0.7, zorder=1))

        root = self.plot[:, 0]
        zeros = np.zeros(self.n_frames)
        ax.plot(root[:, 0], root[:, 1], zeros, color=style.trace_planned, lw=1.0, ls=(0, (3, 2)), zorder=2)
        (self.trace,) = ax.plot([], [], [], color=style.trace, lw=1.8, zorder=3, animated=animated)
        (self.root_dot,) = ax.plot([], [], [], "o", color=style.trace, ms=3.5, zorder=3, animated=animated)

        self.chains = [np.asarray(c) for c in KINEMATIC_CHAIN]
        self.bones = [
            ax.plot([], [], [], color=_chain_colour(c, style), lw=style.bone_width, solid_capstyle="round",
                    zorder=4, animated=animated)[0]
            for c in KINEMATIC_CHAIN
        ]
        (self.head,) = ax.plot([], [], [], "o", color=style.centre, ms=style.head_size, zorder=4, animated=animated)

        el, az = np.radians(style.elev), np.radians(azim)
        for artist in [*ax.collections, *ax.lines]:
            artist.set_clip_on(False)  # the fit in fit_view keeps everything inside the panel
        self._eye = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])

    def set_scale(self, scale: float) -> None:
        """Zoom to ``scale`` display pixels per metre, content centred in :attr:`rect` (at most
        :attr:`fill_scale` keeps it inside)."""
        self.ax.set_position(self.rect)
        self.scale = float(scale)
        fit_view(self.ax, *self._box, self.scale)

    def screen(self, points: np.ndarray) -> np.ndarray:
        """(..., 2) display pixel coordinates of world points (..., 3) (metres, Y-up) on this panel."""
        pts = np.asarray(points, dtype=np.float64)
        return screen_points(self.ax, to_plot(pts.reshape(-1, 3))).reshape(*pts.shape[:-1], 2)

    def frame_index(self, t: int) -> int:
        """Frame shown at global frame ``t``: clips shorter than the animation hold their last frame."""
        return min(max(int(t), 0), self.n_frames - 1)

    def set_frame(self, t: int) -> None:
        """Move the dynamic artists to frame ``t`` (clamped) and order the limbs by depth."""
        i = self.frame_index(t)
        pose = self.plot[i]
        past = self.plot[: i + 1, 0]
        self.trace.set_data_3d(past[:, 0], past[:, 1], np.zeros(len(past)))
        self.root_dot.set_data_3d([past[-1, 0]], [past[-1, 1]], [0.0])
        depth = [float(pose[c].mean(axis=0) @ self._eye) for c in self.chains]
        for rank, k in enumerate(np.argsort(depth)):  # far limbs first
            pts = pose[self.chains[k]]
            self.bones[k].set_data_3d(pts[:, 0], pts[:, 1], pts[:, 2])
            self.bones[k].set_zorder(4 + 0.01 * rank)
        self.head.set_data_3d([pose[HEAD, 0]], [pose[HEAD, 1]], [pose[HEAD, 2]])
        self.head.set_zorder(5)

    def dynamic_artists(self) -> list[Artist]:
        """Dynamic artists in drawing order for the current frame."""
        return sorted([self.trace, self.root_dot, *self.bones, self.head], key=lambda a: a.get_zorder())


def share_scale(panels: Sequence[StickPanel]) -> float:
    """Zoom every panel to the largest scale (display pixels per metre) at which each panel's content
    fits its own rectangle, and return it. Panels are expected to have rectangles of one pixel size."""
    # one metres-per-pixel across panels, so sizes, heights and distances compare between them
    scale = min(p.fill_scale for p in panels)
    for p in panels:
        p.set_scale(scale)
    return scale
