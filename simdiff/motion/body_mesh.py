"""A simple skinned body mesh for the 22-joint skeleton, built from its rest offsets.

The body is a set of closed shapes around the rest skeleton (legs straight down, arms hanging down from the
collars, feet and head bones along +Z, as HumanML3D's ``RAW_OFFSETS`` put them): tapered capsules along the limb
and spine bones, ellipsoids for the pelvis, chest, head and hands, and wedge-shaped rounded boxes along the feet.
Every shape is a stack of rings around a bone axis (superellipse cross-sections), so its vertices know where
they lie along the bone; that gives the skin weights: each shape follows the joint whose rotation turns its bone,
blended linearly with the neighbouring joint over a short distance on either side of each joint (50/50 at the
joint itself), so knees and elbows bend smoothly. Sizes follow the bone lengths (limb radii from each limb's
length, torso widths from the hip and collar spans, head from the neck), so any skeleton gets a fitting body.

Shapes: positions and normals (V, 3) float32 metres, Y up, in the rest pose with the pelvis at ``root``;
triangles (F, 3) uint32, counter-clockwise seen from outside; joints (V, 4) uint8 and weights (V, 4) float32
(at most 3 non-zero influences, summing to 1; unused slots hold joint 0 with weight 0).

:func:`skin` poses the mesh by linear blend skinning as the glTF export binds it
(:mod:`simdiff.motion.io.gltf_writer`): joint j's rest transform is the identity rotation at its rest position,
and its posed transform is its global rotation at its forward-kinematics position, so a vertex bound to j alone
moves rigidly with j and turns with the rotation that turns j's child bones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.rigid import RigidMotion, forward_kinematics, global_rotations
from simdiff.motion.skeleton import NUM_JOINTS, PARENTS, RAW_OFFSETS

LON: int = 16
"""Vertices around each ring."""
CAP_RINGS: int = 4
"""Rings in each rounded end (the pole excluded)."""


@dataclass(frozen=True)
class BodyMesh:
    """A skinned triangle mesh in the rest pose.

    Attributes:
        positions: (V, 3) float32 vertex positions in metres.
        normals: (V, 3) float32 unit vertex normals.
        triangles: (F, 3) uint32 vertex indices, counter-clockwise from outside.
        joints: (V, 4) uint8 joint indices (HumanML3D order) of the influences.
        weights: (V, 4) float32 influence weights, rows summing to 1.
    """

    positions: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray
    joints: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True)
class _Shape:
    """Rings (R, 4) of (axial x, half-width along u, half-depth along v, centre shift along v) in metres around
    the axis ``origin + x * axis``, skinned to ``joint`` and blended with ``start``/``end`` joints at axial
    positions ``x_start``/``x_end`` over ``blend`` metres (joint -1: no blend)."""

    origin: np.ndarray
    axis: np.ndarray
    u: np.ndarray
    v: np.ndarray
    rings: np.ndarray
    joint: int
    start: int = -1
    x_start: float = 0.0
    end: int = -1
    x_end: float = 0.0
    blend: float = 0.05
    power: float = 2.0


def rest_positions(offsets: np.ndarray, root: np.ndarray | None = None) -> np.ndarray:
    """(22, 3) rest joint positions in metres: ``offsets`` (22, 3) accumulated from the pelvis at ``root`` (3,)."""
    offsets = np.asarray(offsets, dtype=np.float64)
    out = np.zeros((NUM_JOINTS, 3))
    out[0] = 0.0 if root is None else np.asarray(root, dtype=np.float64)
    for j in range(1, NUM_JOINTS):
        out[j] = out[PARENTS[j]] + offsets[j]
    return out


def _unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-9 else np.asarray(fallback, dtype=np.float64)


def _frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cross-section axes (u, v) of a bone ``axis``: u the rest lateral (X) direction where it can be, else Y."""
    ref = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = _unit(ref - np.dot(ref, axis) * axis, np.array([0.0, 0.0, 1.0]))
    return u, np.cross(axis, u)


def _capsule_rings(length: float, r0: tuple[float, float], r1: tuple[float, float], cap: float = 1.0,
                   mid: int = 3) -> np.ndarray:
    """Rings (R, 4) of a tapered capsule from x=0 to ``length``: end sizes (half-width, half-depth) ``r0``,
    ``r1``; rounded ends reach ``cap`` times the end's half-width beyond each end."""
    rings = []
    for k in range(CAP_RINGS + 1):  # start cap: pole first
        phi = -np.pi / 2 + k * (np.pi / 2) / CAP_RINGS
        rings.append((cap * r0[0] * np.sin(phi), r0[0] * np.cos(phi), r0[1] * np.cos(phi), 0.0))
    for k in range(1, mid + 1):
        f = k / (mid + 1)
        rings.append((f * length, (1 - f) * r0[0] + f * r1[0], (1 - f) * r0[1] + f * r1[1], 0.0))
    for k in range(CAP_RINGS + 1):
        phi = k * (np.pi / 2) / CAP_RINGS
        rings.append((length + cap * r1[0] * np.sin(phi), r1[0] * np.cos(phi), r1[1] * np.cos(phi), 0.0))
    return np.array(rings)


def _ellipsoid_rings(centre: float, half_axis: float, half_u: float, half_v: float) -> np.ndarray:
    """Rings (R, 4) of an ellipsoid centred at axial ``centre`` with the given semi-axes."""
    phi = np.linspace(-np.pi / 2, np.pi / 2, 2 * CAP_RINGS + 1)
    return np.stack([centre + half_axis * np.sin(phi), half_u * np.cos(phi), half_v * np.cos(phi),
                     np.zeros_like(phi)], axis=-1)


def _tessellate(shape: _Shape) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices (V, 3), triangles (F, 3) and axial coordinates (V,) of one shape (poles as single vertices)."""
    theta = 2 * np.pi * np.arange(LON) / LON
    c, s = np.cos(theta), np.sin(theta)
    e = 2.0 / shape.power
    cu, sv = np.sign(c) * np.abs(c) ** e, np.sign(s) * np.abs(s) ** e
    rings = shape.rings
    inner = rings[1:-1]
    verts = [shape.origin + rings[0, 0] * shape.axis + rings[0, 3] * shape.v]
    xs = [rings[0, 0]]
    for x, a, b, shift in inner:
        ring = (shape.origin + x * shape.axis + shift * shape.v)[None] + (a * cu)[:, None] * shape.u \
            + (b * sv)[:, None] * shape.v
        verts.extend(ring)
        xs.extend([x] * LON)
    verts.append(shape.origin + rings[-1, 0] * shape.axis + rings[-1, 3] * shape.v)
    xs.append(rings[-1, 0])
    tris = []
    k = np.arange(LON)
    k1 = (k + 1) % LON
    tris.append(np.stack([np.zeros(LON, int), 1 + k1, 1 + k], -1))
    for r in range(len(inner) - 1):
        a, b = 1 + r * LON, 1 + (r + 1) * LON
        tris.append(np.stack([a + k, a + k1, b + k1], -1))
        tris.append(np.stack([a + k, b + k1, b + k], -1))
    last = len(verts) - 1
    base = 1 + (len(inner) - 1) * LON
    tris.append(np.stack([np.full(LON, last), base + k, base + k1], -1))
    verts_arr, tris_arr = np.array(verts), np.concatenate(tris)
    # orient outwards: positive signed volume
    p = verts_arr[tris_arr]
    if np.einsum("fi,fi->f", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() < 0:
        tris_arr = tris_arr[:, ::-1]
    return verts_arr, tris_arr, np.array(xs)


def _normals(verts: np.ndarray, tris: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Area-weighted smooth vertex normals (V, 3); degenerate ones point away from ``centre``."""
    p = verts[tris]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    out = np.zeros_like(verts)
    for corner in range(3):
        np.add.at(out, tris[:, corner], face)
    norm = np.linalg.norm(out, axis=-1, keepdims=True)
    radial = verts - centre
    radial /= np.maximum(np.linalg.norm(radial, axis=-1, keepdims=True), 1e-12)
    return np.where(norm > 1e-12, out / np.maximum(norm, 1e-12), radial)


def _weights(shape: _Shape, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joint indices (V, 4) and weights (V, 4): linear blends around the shape's two end joints."""
    n = len(xs)
    w_start = np.zeros(n) if shape.start < 0 else np.clip(0.5 - (xs - shape.x_start) / (2 * shape.blend), 0, 1)
    w_end = np.zeros(n) if shape.end < 0 else np.clip(0.5 + (xs - shape.x_end) / (2 * shape.blend), 0, 1)
    total = w_start + w_end
    scale = np.where(total > 1, 1 / np.maximum(total, 1e-12), 1.0)
    w_start, w_end = (w_start * scale).astype(np.float32), (w_end * scale).astype(np.float32)
    w_main = np.float32(1) - w_start - w_end
    weights = np.stack([w_main, w_start, w_end, np.zeros(n, np.float32)], -1)
    joints = np.tile(np.array([shape.joint, max(shape.start, 0), max(shape.end, 0), 0]), (n, 1))
    joints[weights == 0] = 0
    order = np.argsort(-weights, axis=-1, kind="stable")
    return np.take_along_axis(joints, order, -1), np.take_along_axis(weights, order, -1)


def _bone(p: np.ndarray, a: int, b: int) -> tuple[np.ndarray, float]:
    """Unit direction and length of the rest bone from joint ``a`` to joint ``b``."""
    d = p[b] - p[a]
    return _unit(d, RAW_OFFSETS[b]), float(np.linalg.norm(d))


def _limb(p: np.ndarray, a: int, b: int, r0: float, r1: float, start: int, end: int, flat: float = 1.0) -> _Shape:
    """A tapered capsule on the bone a → b skinned to ``a``, radii ``r0``/``r1`` (depth = ``flat`` × width)."""
    axis, length = _bone(p, a, b)
    u, v = _frame(axis)
    rings = _capsule_rings(length, (r0, r0 * flat), (r1, r1 * flat), cap=0.8)
    blend = max(min(0.35 * max(r0, r1), 0.5 * length), 1e-3)
    return _Shape(p[a], axis, u, v, rings, a, start, 0.0, end, length, blend)


def _sizes(p: np.ndarray) -> dict[str, float]:
    """Body measures in metres from the rest joints."""
    def length(a: int, b: int) -> float:
        return float(np.linalg.norm(p[b] - p[a]))

    spine = length(0, 3) + length(3, 6) + length(6, 9) + length(9, 12)
    return {"spine": max(spine, 1e-3), "hips": max(length(1, 2), 1e-3), "collars": max(length(13, 14), 1e-3),
            "head": max(length(9, 12) * 0.5 + length(12, 15), 1e-3)}


def _shapes(p: np.ndarray) -> list[_Shape]:
    """Every shape of the body around rest joints ``p`` (22, 3)."""
    m = _sizes(p)
    shapes: list[_Shape] = []
    for hip, knee, ankle, foot in ((1, 4, 7, 10), (2, 5, 8, 11)):
        thigh, shin = np.linalg.norm(p[knee] - p[hip]), np.linalg.norm(p[ankle] - p[knee])
        shapes.append(_limb(p, hip, knee, 0.19 * thigh, 0.13 * thigh, 0, knee))
        shapes.append(_limb(p, knee, ankle, 0.13 * shin, 0.08 * shin, hip, ankle))
        shapes.append(_foot(p, ankle, foot, knee))
    for collar, shoulder, elbow, wrist in ((13, 16, 18, 20), (14, 17, 19, 21)):
        cl, up, fore = (np.linalg.norm(p[b] - p[a]) for a, b in ((collar, shoulder), (shoulder, elbow),
                                                                  (elbow, wrist)))
        shapes.append(_limb(p, collar, shoulder, 0.34 * cl, 0.36 * cl, 9, shoulder))
        shapes.append(_limb(p, shoulder, elbow, 0.19 * up, 0.14 * up, collar, elbow))
        shapes.append(_limb(p, elbow, wrist, 0.14 * fore, 0.09 * fore, shoulder, -1))
        axis, _ = _bone(p, elbow, wrist)
        u, v = _frame(axis)
        rings = _ellipsoid_rings(0.32 * fore, 0.36 * fore, 0.09 * fore, 0.17 * fore)
        shapes.append(_Shape(p[wrist], axis, u, v, rings, wrist))
    hips, collars, spine = m["hips"], m["collars"], m["spine"]
    widths = {0: (0.62 * hips, 0.17 * spine), 3: (0.58 * hips, 0.16 * spine), 6: (0.62 * hips, 0.17 * spine),
              9: (0.50 * collars, 0.19 * spine)}
    for a, b in ((0, 3), (3, 6), (6, 9)):
        axis, length = _bone(p, a, b)
        u, v = _frame(axis)
        rings = _capsule_rings(length, widths[a], widths[b], cap=0.3, mid=2)
        shapes.append(_Shape(p[a], axis, u, v, rings, a, PARENTS[a] if a else -1, 0.0, b, length,
                             max(min(0.4 * length, 0.08), 1e-3)))
    u, v = _frame(np.array([0.0, 1.0, 0.0]))
    shapes.append(_Shape(p[0], np.array([0.0, 1.0, 0.0]), u, v,
                         _ellipsoid_rings(-0.04 * spine, 0.2 * spine, 0.8 * hips, 0.2 * spine), 0))
    axis, length = _bone(p, 9, 12)
    u, v = _frame(axis)
    shapes.append(_Shape(p[9], axis, u, v, _ellipsoid_rings(0.2 * length, 0.75 * length, 0.62 * collars,
                                                               0.2 * spine), 9, 6, 0.0, -1, 0.0,
                         max(0.3 * length, 1e-3)))
    shapes.append(_limb(p, 9, 12, 0.3 * collars, 0.2 * collars, 6, 12, flat=0.8))
    head = m["head"]
    shapes.append(_limb(p, 12, 15, 0.2 * head, 0.2 * head, 9, -1))
    axis, _ = _bone(p, 12, 15)
    u, v = _frame(axis)
    shapes.append(_Shape(p[15], axis, u, v, _ellipsoid_rings(0.4 * head, 0.5 * head, 0.38 * head, 0.45 * head),
                         15))
    return shapes


def _foot(p: np.ndarray, ankle: int, toe: int, knee: int) -> _Shape:
    """A rounded wedge along the foot bone: deep under the ankle, thin at the toes, heel behind the ankle; the
    sole drops 0.3 bone lengths below the ankle and 0.04 below the toe joint, as a foot flat on the floor
    has them (HumanML3D: ankle about 5 cm, toe joint under 1 cm above the ground)."""
    axis, length = _bone(p, ankle, toe)
    length = max(length, 1e-3)
    u, v = _frame(axis)
    up = v if np.dot(v, [0.0, 1.0, 0.0]) >= 0 else -v
    v = up  # depth axis pointing up in the rest pose, so the sole lies below the bone
    u = np.cross(v, axis)
    heel, tip = -0.35 * length, 1.2 * length
    xs = np.linspace(heel, tip, 9)
    top = np.interp(xs, [heel, 0, length, tip], [0.12, 0.2, 0.13, 0.08]) * length
    bottom = np.interp(xs, [heel, 0, length, tip], [-0.28, -0.3, -0.04, 0.02]) * length
    half_w = np.interp(xs, [heel, 0, length, tip], [0.2, 0.24, 0.3, 0.22]) * length
    rings = np.stack([xs, half_w, (top - bottom) / 2, (top + bottom) / 2], -1)
    ends = [(heel - 0.06 * length, 0.0, 0.0, rings[0, 3]), (tip + 0.06 * length, 0.0, 0.0, rings[-1, 3])]
    rings = np.vstack([ends[0], rings, ends[1]])
    return _Shape(p[ankle], axis, u, v, rings, ankle, knee, 0.0, -1, 0.0, 0.15 * length, power=3.0)


def build_body(offsets: np.ndarray, root: np.ndarray | None = None) -> BodyMesh:
    """A skinned body around the rest skeleton ``offsets`` (22, 3) metres, pelvis at ``root`` (3,) (default 0).

    Raises:
        SimdiffError: offsets not a finite (22, 3) array.
    """
    offsets = np.asarray(offsets, dtype=np.float64)
    if offsets.shape != (NUM_JOINTS, 3) or not np.all(np.isfinite(offsets)):
        raise SimdiffError(f"a body mesh needs finite (22, 3) offsets, got shape {offsets.shape}")
    p = rest_positions(offsets, root)
    positions, normals, triangles, joints, weights = [], [], [], [], []
    count = 0
    for shape in _shapes(p):
        verts, tris, xs = _tessellate(shape)
        positions.append(verts)
        normals.append(_normals(verts, tris, verts.mean(axis=0)))
        triangles.append(tris + count)
        j, w = _weights(shape, xs)
        joints.append(j)
        weights.append(w)
        count += len(verts)
    w = np.concatenate(weights).astype(np.float32)
    return BodyMesh(np.concatenate(positions).astype(np.float32), np.concatenate(normals).astype(np.float32),
                    np.concatenate(triangles).astype(np.uint32), np.concatenate(joints).astype(np.uint8), w)


SKIN_CHUNK: int = 64
"""Frames posed at once by :func:`skin` (bounds its temporary memory to about 30 MB)."""


def skin(mesh: BodyMesh, motion: RigidMotion, root: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and unit normals (T, V, 3) float32 of ``mesh`` posed by ``motion`` (linear blend skinning).

    Args:
        mesh: built by :func:`build_body` from ``motion.offsets`` with its pelvis at ``root``.
        motion: local rotations (T, 22, 3, 3), pelvis path (T, 3) and offsets (22, 3), metres, Y up.
        root: (3,) the rest pelvis position ``mesh`` was built with (default 0, as :func:`build_body`).
    Returns:
        Per frame Σ_k w_k (G_k (x − r_k) + p_k) for each vertex x with joints k and weights w_k, G the global
        rotations, r the rest joint positions and p the posed ones; normals are the blended rotations applied
        to the rest normals, renormalised.
    Raises:
        SimdiffError: mesh and motion of different joint counts or non-finite values.
    """
    local = np.asarray(motion.local, dtype=np.float64)
    path = np.asarray(motion.root, dtype=np.float64)
    if local.ndim != 4 or local.shape[1:] != (NUM_JOINTS, 3, 3) or path.shape != (len(local), 3):
        raise SimdiffError(f"skin needs (T, 22, 3, 3) rotations and a (T, 3) root, got {local.shape} and {path.shape}")
    rest = rest_positions(motion.offsets, root)
    idx, w = mesh.joints.astype(np.intp), mesh.weights.astype(np.float64)
    x, n = mesh.positions.astype(np.float64), mesh.normals.astype(np.float64)
    verts = np.empty((len(local), len(x), 3), np.float32)
    normals = np.empty_like(verts)
    for a in range(0, len(local), SKIN_CHUNK):
        glob = global_rotations(local[a:a + SKIN_CHUNK])  # (t, 22, 3, 3)
        shift = forward_kinematics(local[a:a + SKIN_CHUNK], path[a:a + SKIN_CHUNK], motion.offsets) \
            - np.einsum("tjab,jb->tja", glob, rest)  # (t, 22, 3): p_j − G_j r_j
        rot = np.einsum("vk,tvkab->tvab", w, glob[:, idx])  # (t, V, 3, 3) blended rotations
        verts[a:a + SKIN_CHUNK] = np.einsum("tvab,vb->tva", rot, x) + np.einsum("vk,tvka->tva", w, shift[:, idx])
        turned = np.einsum("tvab,vb->tva", rot, n)
        normals[a:a + SKIN_CHUNK] = turned / np.maximum(np.linalg.norm(turned, axis=-1, keepdims=True), 1e-12)
    if not (np.all(np.isfinite(verts)) and np.all(np.isfinite(normals))):
        raise SimdiffError("skin: the motion contains NaN or infinite values")
    return verts, normals
