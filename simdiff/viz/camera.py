"""Cameras that keep a whole clip in view.

Stick figures (matplotlib): a fixed camera per clip, bounds, viewing azimuth and zoom
computed once from the whole clip. Plot coordinates are matplotlib's Z-up frame,
``(x, -z, y)`` of the Y-up world (a proper rotation, so nothing is mirrored).

Body renders (MuJoCo, world Z-up): :class:`BodyCamera`, a perspective camera that follows the
smoothed root horizontally, with one distance, look-at height, azimuth and elevation shared
by every panel, chosen by :func:`fit_body_camera` so that every geom of every frame is inside
the image with a margin.
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


def geom_boxes(model, qpos: np.ndarray, every: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World boxes bounding the humanoid's geoms in each state: centres (T, G, 3), axes (T, G, 3, 3), half sizes (G, 3).

    Each geom's box is its local axis-aligned bounding box (``geom_aabb``) carried by the
    geom's pose; geoms of the world body (the floor) are left out. ``every``: keep one state
    in ``every`` (the last one always).
    """
    import mujoco

    keep = np.flatnonzero(model.geom_bodyid != 0)
    q = np.asarray(qpos, dtype=np.float64)
    idx = np.unique(np.r_[np.arange(0, len(q), max(int(every), 1)), len(q) - 1])
    data = mujoco.MjData(model)
    centres = np.empty((len(idx), len(keep), 3))
    axes = np.empty((len(idx), len(keep), 3, 3))
    for k, t in enumerate(idx):
        data.qpos[:] = q[t]
        mujoco.mj_kinematics(model, data)
        rot = data.geom_xmat[keep].reshape(-1, 3, 3)
        centres[k] = data.geom_xpos[keep] + np.einsum("gij,gj->gi", rot, model.geom_aabb[keep, :3])
        axes[k] = rot
    return centres, axes, model.geom_aabb[keep, 3:].copy()


def point_boxes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World points (T, N, 3) as zero-size boxes, in the form of :func:`geom_boxes`."""
    pts = np.asarray(points, dtype=np.float64)
    axes = np.broadcast_to(np.eye(3), (*pts.shape[:2], 3, 3))
    return pts, axes, np.zeros((pts.shape[1], 3))


def join_boxes(a: tuple[np.ndarray, np.ndarray, np.ndarray],
               b: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The boxes of ``a`` and ``b`` (same states) together."""
    return (np.concatenate([a[0], b[0]], axis=1), np.concatenate([a[1], b[1]], axis=1),
            np.concatenate([a[2], b[2]], axis=0))


def _support(centres: np.ndarray, axes: np.ndarray, half: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(T,) the largest value of the linear form ``w`` (T, 3) over each state's boxes."""
    local = np.abs(np.einsum("tgij,ti->tgj", axes, w))  # |R^T w| per box
    return (np.einsum("tgi,ti->tg", centres, w) + (local * half).sum(axis=-1)).max(axis=1)


def fit_body_camera(boxes: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]], lookats: Sequence[np.ndarray],
                    camera: BodyCamera, aspect: float) -> tuple[BodyCamera, list[np.ndarray]]:
    """The distance, look-at height and sideways shifts that keep every box of every state in view.

    Args:
        boxes: per panel, :func:`geom_boxes` of its states.
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
    tx = ty * aspect
    big = np.full(3, -np.inf)  # sideways bound, top bound, bottom bound
    shifts = []
    for (centres, axes, half), look in zip(boxes, lookats):
        origin = np.asarray(look, dtype=np.float64)[:, None, :].copy()
        origin[..., 2] = 0.0
        rel = centres - origin
        n = len(rel)
        forms = [right / tx - forward, -right / tx - forward, up / ty - forward, -up / ty - forward]
        p, q, top, bottom = [_support(rel, axes, half, np.broadcast_to(w, (n, 3))).max() for w in forms]
        shifts.append(tx * (p - q) / 2 * right)  # d >= max(p - s/tx, q + s/tx) is least at s = tx (p - q) / 2
        big = np.maximum(big, [(p + q) / 2, top, bottom])
    # at look-at height z: d >= A + fz z (sides), B + (fz - k) z (top), C + (fz + k) z (bottom), k = uz / ty;
    # the height that balances top and bottom centres the content vertically
    k = up[2] / ty
    best = (big[1] - big[2]) / (2 * k)
    distance = max(float(np.max(big + np.array([0.0, -k, k]) * best + forward[2] * best)), camera.min_distance)
    return replace(camera, distance=distance, height=float(best)), shifts


def camera_path(qpos: np.ndarray, fps: float, camera: BodyCamera = BodyCamera()) -> np.ndarray:
    """(T, 3) world look-at points: the root path, Gaussian-smoothed over ``camera.smooth_s``.

    The height is ``camera.height`` (the fitted one when the camera was fitted), or the
    smoothed root height with ``follow_height``.
    """
    from scipy.ndimage import gaussian_filter1d

    root = np.asarray(qpos, dtype=np.float64)[:, :3].copy()
    sigma = camera.smooth_s * fps
    if sigma > 0 and len(root) > 1:
        root = gaussian_filter1d(root, sigma, axis=0, mode="nearest")
    if not camera.follow_height:
        root[:, 2] = camera.height
    return root
