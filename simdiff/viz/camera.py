"""Cameras that keep a whole clip in view.

Stick figures (matplotlib): a fixed orthographic camera per clip, bounds and viewing azimuth
computed once from the whole clip, zoomed to a scale in display pixels per metre (the
renders share one scale across their panels). Plot coordinates are matplotlib's Z-up frame,
``(x, -z, y)`` of the Y-up world (a proper rotation, so nothing is mirrored).

Body renders (MuJoCo, world Z-up): :class:`BodyCamera`, a perspective camera that follows the
smoothed root horizontally, with one distance, look-at height, azimuth and elevation shared
by every panel, chosen by :func:`fit_body_camera` so that every body vertex of every frame is
inside the image with a margin.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Sequence

import numpy as np

if TYPE_CHECKING:
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


def content_extent(motion: np.ndarray, elev: float, azim: float | None) -> tuple[float, float]:
    """(width, height) in metres of a clip's content (:func:`content_points`) seen orthographically from
    (elev, azim) degrees; ``azim`` None: :func:`choose_azim` of the clip."""
    lo, hi = clip_bounds(motion)
    pts = content_points(motion, lo, hi)
    right, up = view_basis(elev, choose_azim(motion) if azim is None else azim)
    return float(np.ptp(pts @ right)), float(np.ptp(pts @ up))


def content_aspect(motion: np.ndarray, elev: float, azim: float | None) -> float:
    """Height / width of a clip's content seen orthographically from (elev, azim) degrees."""
    w, h = content_extent(motion, elev, azim)
    return h / max(w, 1e-9)


def auto_height(motions: list[np.ndarray], width: float, elev: float, azim: float | None,
                lo_ratio: float = 0.45, hi_ratio: float = 1.4) -> float:
    """Panel height (unit of ``width``) for clips drawn at one shared scale, clamped to [lo_ratio, hi_ratio] * width.

    At the scale that fits the widest content across ``width``, the tallest content needs
    ``width * max height / max width``; for one clip this is its own height / width.
    """
    extents = np.array([content_extent(m, elev, azim) for m in motions])
    ratio = extents[:, 1].max() / max(float(extents[:, 0].max()), 1e-9)
    return width * float(np.clip(ratio, lo_ratio, hi_ratio))


def screen_points(ax: Axes3D, points: np.ndarray) -> np.ndarray:
    """(N, 2) display pixel coordinates of plot-space ``points`` (N, 3) under ``ax``'s current projection."""
    h = np.concatenate([points, np.ones((len(points), 1))], axis=1) @ ax.get_proj().T
    return ax.transData.transform(h[:, :2] / h[:, 3:4])


def _unit_zoom(ax: Axes3D, lo: np.ndarray, hi: np.ndarray, points: np.ndarray, pad_px: float
               ) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """Project at zoom 1 from ``ax``'s original rectangle.

    Returns:
        Box centre (2,) and ``points`` (N, 2) in display pixels, the scale at zoom 1 in pixels per
        metre, and the free size (2,) of the rectangle in pixels once ``pad_px`` is kept on every side.
    """
    ax.set_box_aspect(tuple(hi - lo), zoom=1.0)
    ax.apply_aspect()
    centre = (lo + hi) / 2
    right, _ = view_basis(ax.elev, ax.azim)
    c, r = screen_points(ax, np.stack([centre, centre + right]))
    fig = ax.get_figure()
    box = ax.get_position(original=True).transformed(fig.transFigure)
    free = np.array([box.width, box.height]) - 2 * pad_px * fig.dpi / 100.0
    return c, screen_points(ax, points), float(np.hypot(*(r - c))), free


def fill_scale(ax: Axes3D, lo: np.ndarray, hi: np.ndarray, points: np.ndarray, pad_px: float = 6.0) -> float:
    """Largest scale (display pixels per metre) at which ``points`` (N, 3, plot space) fit in ``ax``'s original
    rectangle, ``pad_px`` (at 100 dpi) kept free on every side; ``lo``, ``hi`` the axes' data box.

    Assumes an orthographic camera and a box aspect equal to ``hi - lo``, under which one metre has
    the same screen length in every direction.
    """
    _, xy, unit, free = _unit_zoom(ax, lo, hi, points, pad_px)
    size = np.maximum(np.ptp(xy, axis=0), 1e-9)
    return unit * float(min(free[0] / size[0], free[1] / size[1]))


def fit_view(ax: Axes3D, lo: np.ndarray, hi: np.ndarray, points: np.ndarray, scale: float) -> None:
    """Zoom ``ax`` to ``scale`` display pixels per metre and shift it so ``points`` (N, 3, plot space) are centred
    in its original rectangle; ``lo``, ``hi`` the axes' data box.

    Under an orthographic camera, screen offsets from the projected box centre are linear in the
    zoom. Axes3D does not clip its artists to the axes, so the axes may be moved.
    """
    centre, xy, unit, _ = _unit_zoom(ax, lo, hi, points, 0.0)
    panel = ax.get_position(original=True)
    fig = ax.get_figure()
    box = panel.transformed(fig.transFigure)
    zoom = max(scale / unit, 1e-3)
    ax.set_box_aspect(tuple(hi - lo), zoom=zoom)
    zoomed_centre = centre + zoom * ((xy.min(axis=0) + xy.max(axis=0)) / 2 - centre)
    shift = (np.array([box.x0 + box.width / 2, box.y0 + box.height / 2]) - zoomed_centre) / fig.bbox.size
    ax.set_position(panel.translated(shift[0], shift[1]))


# --------------------------------------------------------------------------------------
# body renders: a perspective camera fitted to the whole clip
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BodyCamera:
    """A MuJoCo free camera that follows the root.

    Attributes:
        distance: camera to look-at point (m); replaced by the fitted distance when ``fit``.
        azimuth: viewing direction in the ground plane (degrees, MuJoCo convention: 90 looks
            along world +y). The character faces world +x (HumanML3D +Z) at rest, so the
            default 120 sees it from its front right.
        elevation: degrees, negative looks down.
        height: look-at height above the floor (m) when neither ``fit`` nor ``follow_height``.
        follow_height: without ``fit``, the look-at point also follows the root height.
        smooth_s: Gaussian smoothing of the root path (s), so that gait sway does not shake
            the image.
        fovy: vertical field of view (degrees).
        fit: choose ``distance`` and one look-at height for the whole render from the motions
            (:func:`fit_body_camera`), so nothing is ever cropped.
        margin: with ``fit``, the free border kept on every side, as a fraction of the image's
            half-width and half-height (0.12: 6 % of the image width on the left and on the right).
        min_distance: with ``fit``, the closest the camera comes (m), so small motions are not
            blown up.
    """

    distance: float = 3.4
    azimuth: float = 120.0
    elevation: float = -14.0
    height: float = 0.85
    follow_height: bool = False
    smooth_s: float = 0.5
    fovy: float = 45.0
    fit: bool = True
    margin: float = 0.12
    min_distance: float = 2.0


def camera_axes(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World (Z-up) unit vectors (forward, up, right) of a MuJoCo free camera at these angles (degrees)."""
    az, el = np.radians(azimuth), np.radians(elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    up = np.array([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), np.cos(el)])
    right = np.array([np.sin(az), -np.cos(az), 0.0])
    return forward, up, right


def project(points: np.ndarray, lookat: np.ndarray, camera: BodyCamera, width: int, height: int) -> np.ndarray:
    """Pixel coordinates (..., 2) as (column, row from the top) of world points (..., 3).

    MuJoCo's free-camera math: the eye is ``distance`` behind ``lookat`` along the forward
    axis, the frustum is symmetric with vertical field of view ``fovy`` and the width follows
    the image aspect. ``lookat`` (3,) or broadcastable to ``points``. Points behind the camera
    get NaN.
    """
    forward, up, right = camera_axes(camera.azimuth, camera.elevation)
    v = np.asarray(points, dtype=np.float64) - np.asarray(lookat, dtype=np.float64) + camera.distance * forward
    depth = v @ forward
    depth = np.where(depth > 1e-9, depth, np.nan)
    ty = np.tan(np.radians(camera.fovy) / 2)
    ndc_x = (v @ right) / depth / (ty * width / height)
    ndc_y = (v @ up) / depth / ty
    return np.stack([(ndc_x + 1) / 2 * width, (1 - ndc_y) / 2 * height], axis=-1)


def point_boxes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World points (T, N, 3) as zero-size boxes (T, N, 3) centres, (T, N, 3, 3) axes, (N, 3) half sizes."""
    pts = np.asarray(points, dtype=np.float64)
    axes = np.broadcast_to(np.eye(3), (*pts.shape[:2], 3, 3))
    return pts, axes, np.zeros((pts.shape[1], 3))


def _support(centres: np.ndarray, axes: np.ndarray, half: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(T,) the largest value of the linear form ``w`` (T, 3) over each state's boxes."""
    local = np.abs(np.einsum("tgij,ti->tgj", axes, w))  # |R^T w| per box
    return (np.einsum("tgi,ti->tg", centres, w) + (local * half).sum(axis=-1)).max(axis=1)


def _forms(camera: BodyCamera, aspect: float) -> np.ndarray:
    """(4, 3) the linear forms whose largest values over the content bound the view: right, left, top, bottom."""
    forward, up, right = camera_axes(camera.azimuth, camera.elevation)
    ty = np.tan(np.radians(camera.fovy) / 2) * (1.0 - camera.margin)
    tx = ty * aspect
    return np.array([right / tx - forward, -right / tx - forward, up / ty - forward, -up / ty - forward])


def extreme_points(points: np.ndarray, camera: BodyCamera, aspect: float) -> np.ndarray:
    """(T, 4, 3) the points of each state (T, N, 3) that bound the view on the right, left, top and bottom.

    :func:`fit_body_camera` of these points equals its fit of all ``points`` (each bound is the largest value
    of a linear form, and a look-at shift moves every point of a state alike), for this camera's angles, fovy
    and margin and this ``aspect`` (width / height).
    """
    pts = np.asarray(points, dtype=np.float64)
    best = np.argmax(pts @ _forms(camera, aspect).T, axis=1)  # (T, 4)
    return np.take_along_axis(pts, best[..., None], axis=1)


def fit_body_camera(boxes: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]], lookats: Sequence[np.ndarray],
                    camera: BodyCamera, aspect: float) -> tuple[BodyCamera, list[np.ndarray]]:
    """The distance, look-at height and sideways shifts that keep every box of every state in view.

    Args:
        boxes: per panel, world boxes (centres (T, N, 3), axes (T, N, 3, 3), half sizes (N, 3)) of its
            states, e.g. :func:`point_boxes` of its body vertices or of their :func:`extreme_points`.
        lookats: per panel, the (T, 3) horizontal look-at path of the same states (its z is
            ignored: one look-at height is chosen for all panels and frames).
        camera: azimuth, elevation, fovy and margin to keep; ``min_distance`` bounds the result.
        aspect: image width / height.
    Returns:
        ``camera`` with ``distance`` (at least ``min_distance``) and ``height`` set, shared by
        all panels, and per panel a constant world shift (3,) of its look-at path along the
        camera's horizontal right axis that centres the panel's content sideways. The height
        centres the content vertically and the distance is the smallest, at that height, for
        which every box lies within ``1 - margin`` of the image's half-width and half-height in
        every frame of every panel.

    A point ``p`` seen from look-at ``L`` at distance ``d`` is in view when
    ``|(p - L)·right| <= tx ((p - L)·forward + d)`` and likewise for ``up`` with ``ty``; each
    bound is linear in ``d``, in the look-at height and in the sideways shift, so the tightest
    over all boxes reduces to a few numbers: the shift that balances the left and right bounds,
    the height that balances the top and bottom bounds, and the distance that meets all.
    """
    forward, up, right = camera_axes(camera.azimuth, camera.elevation)
    ty = np.tan(np.radians(camera.fovy) / 2) * (1.0 - camera.margin)
    big = np.full(3, -np.inf)  # sideways bound, top bound, bottom bound
    shifts = []
    for (centres, axes, half), look in zip(boxes, lookats):
        origin = np.asarray(look, dtype=np.float64)[:, None, :].copy()
        origin[..., 2] = 0.0
        rel = centres - origin
        n = len(rel)
        p, q, top, bottom = [_support(rel, axes, half, np.broadcast_to(w, (n, 3))).max()
                             for w in _forms(camera, aspect)]
        shifts.append(ty * aspect * (p - q) / 2 * right)  # d >= max(p - s/tx, q + s/tx) is least at s = tx (p - q) / 2
        big = np.maximum(big, [(p + q) / 2, top, bottom])
    # at look-at height z: d >= A + fz z (sides), B + (fz - k) z (top), C + (fz + k) z (bottom), k = uz / ty;
    # the height that balances top and bottom centres the content vertically
    k = up[2] / ty
    best = (big[1] - big[2]) / (2 * k)
    distance = max(float(np.max(big + np.array([0.0, -k, k]) * best + forward[2] * best)), camera.min_distance)
    return replace(camera, distance=distance, height=float(best)), shifts


def camera_path(root: np.ndarray, fps: float, camera: BodyCamera = BodyCamera()) -> np.ndarray:
    """(T, 3) world look-at points: the pelvis path ``root`` (T, 3) world metres, Gaussian-smoothed over
    ``camera.smooth_s``.

    The height is ``camera.height`` (the fitted one when the camera was fitted), or the
    smoothed root height with ``follow_height``.
    """
    from scipy.ndimage import gaussian_filter1d

    root = np.array(root, dtype=np.float64)
    sigma = camera.smooth_s * fps
    if sigma > 0 and len(root) > 1:
        root = gaussian_filter1d(root, sigma, axis=0, mode="nearest")
    if not camera.follow_height:
        root[:, 2] = camera.height
    return root
