"""A fixed camera per clip: bounds, viewing azimuth and zoom computed once from the whole clip.

Plot coordinates are matplotlib's Z-up frame, ``(x, -z, y)`` of the Y-up world (a proper
rotation, so nothing is mirrored).
"""

from __future__ import annotations

import numpy as np
from mpl_toolkits.mplot3d import Axes3D

DEFAULT_AZIM: float = -60.0
"""Plot-space azimuth in degrees: a 3/4 front view of a figure facing world +Z."""


def to_plot(points: np.ndarray) -> np.ndarray:
    """World (..., 3) Y-up points -> matplotlib Z-up plot coordinates (x, -z, y)."""
    return np.stack([points[..., 0], -points[..., 2], points[..., 1]], axis=-1)


def clip_bounds(motion: np.ndarray, margin: float = 0.25, min_span: float = 1.2) -> tuple[np.ndarray, np.ndarray]:
    """Fixed plot-space box (lo, hi), each (3,), containing the whole clip and the floor.

    Args:
        motion: (T, 22, 3) world joints in metres.
        margin: horizontal padding in metres.
        min_span: smallest horizontal side in metres (keeps a standing figure in context).
    """
    pts = to_plot(motion.reshape(-1, 3))
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = (lo[:2] + hi[:2]) / 2
    half = np.maximum((hi[:2] - lo[:2]) / 2 + margin, min_span / 2)
    top = max(float(hi[2]), 0.0) + 0.1
    bottom = min(float(lo[2]), 0.0)
    return np.array([*(centre - half), bottom]), np.array([*(centre + half), top])


def choose_azim(motion: np.ndarray, min_travel: float = 1.0, front_angle: float = 30.0) -> float:
    """Plot-space azimuth (degrees) for a clip.

    Clips that travel less than ``min_travel`` metres get :data:`DEFAULT_AZIM`. Travelling clips
    are seen from the side of their main direction of travel (so the path spreads across the
    image), on the side the figure faces at frame 0, turned ``front_angle`` degrees forward.
    """
    root = motion[:, 0][:, [0, 2]].astype(np.float64)  # (T, 2) world x, z
    centred = root - root.mean(axis=0)
    if len(root) < 2:
        return DEFAULT_AZIM
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    travel = vt[0]
    extent = float(np.ptp(centred @ travel))
    if extent < min_travel:
        return DEFAULT_AZIM
    across = motion[0, 1] - motion[0, 2]  # left hip - right hip
    facing = np.array([-across[2], across[0]])  # horizontal cross(across, up) as (x, z)
    side = np.array([-travel[1], travel[0]])
    if side @ facing < 0:
        side = -side
    if travel @ facing < 0:
        travel = -travel
    a = np.radians(front_angle)
    eye = np.cos(a) * side + np.sin(a) * travel  # world (x, z)
    return float(np.degrees(np.arctan2(-eye[1], eye[0])))  # plot (x, -z)


def content_points(motion: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(N, 3) plot-space points that must stay in view: every joint of every frame and the floor corners."""
    floor = np.array([[x, y, 0.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
    return np.concatenate([to_plot(motion.reshape(-1, 3)), floor])


def view_basis(elev: float, azim: float) -> tuple[np.ndarray, np.ndarray]:
    """Plot-space unit vectors pointing right and up on screen for a camera at (elev, azim) degrees."""
    el, az = np.radians(elev), np.radians(azim)
    right = np.array([-np.sin(az), np.cos(az), 0.0])
    up = np.array([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), np.cos(el)])
    return right, up


def content_aspect(motion: np.ndarray, elev: float, azim: float | None) -> float:
    """Height / width of a clip's content seen orthographically from (elev, azim) degrees."""
    lo, hi = clip_bounds(motion)
    pts = content_points(motion, lo, hi)
    right, up = view_basis(elev, choose_azim(motion) if azim is None else azim)
    return float(np.ptp(pts @ up) / max(np.ptp(pts @ right), 1e-9))


def auto_height(motions: list[np.ndarray], width: float, elev: float, azim: float | None,
                lo_ratio: float = 0.45, hi_ratio: float = 1.4) -> float:
    """Panel height (unit of ``width``) fitting the tallest clip, clamped to [lo_ratio, hi_ratio] * width."""
    ratio = max(content_aspect(m, elev, azim) for m in motions)
    return width * float(np.clip(ratio, lo_ratio, hi_ratio))


def fit_view(ax: Axes3D, lo: np.ndarray, hi: np.ndarray, points: np.ndarray, pad_px: float = 6.0) -> None:
    """Zoom and shift ``ax`` so ``points`` (N, 3, plot space) fill its original rectangle, centred.

    Assumes an orthographic camera, under which screen offsets from the projected box centre are
    linear in the zoom. Axes3D does not clip its artists to the axes, so the axes may be moved.
    """
    aspect = tuple(hi - lo)
    panel = ax.get_position(original=True)
    ax.set_box_aspect(aspect, zoom=1.0)
    ax.apply_aspect()
    m = ax.get_proj()

    def screen(p: np.ndarray) -> np.ndarray:
        h = np.concatenate([p, np.ones((len(p), 1))], axis=1) @ m.T
        return ax.transData.transform(h[:, :2] / h[:, 3:4])

    centre = screen(((lo + hi) / 2)[None])[0]
    xy = screen(points)
    pmin, pmax = xy.min(axis=0), xy.max(axis=0)
    fig = ax.get_figure()
    box = panel.transformed(fig.transFigure)
    pad = pad_px * fig.dpi / 100.0
    size = np.maximum(pmax - pmin, 1e-9)
    zoom = min((box.width - 2 * pad) / size[0], (box.height - 2 * pad) / size[1])
    ax.set_box_aspect(aspect, zoom=max(zoom, 1e-3))
    new_centre = centre + zoom * ((pmin + pmax) / 2 - centre)
    shift = (np.array([box.x0 + box.width / 2, box.y0 + box.height / 2]) - new_centre) / fig.bbox.size
    ax.set_position(panel.translated(shift[0], shift[1]))
