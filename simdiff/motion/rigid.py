"""A rigid skeleton by construction: local joint rotations on one fixed skeleton, fitted to joint positions.

Joint positions recovered from the network drift in bone length; animation tools expect rotations on fixed bones.
:func:`fit` solves local rotations on a fixed skeleton (by default HumanML3D's canonical bones, which every corpus
clip has) that aim every bone where the positions put it, and :func:`forward_kinematics` turns rotations back into
positions. Branching joints (pelvis: hips and spine1; spine3: neck and collars) get the rotation that best fits
their three children (Kabsch); chain joints the shortest rotation, relative to their parent, that aims the bone from
the already-placed parent at its target; leaves (head, feet, wrists) the identity. Bone directions are kept, so the
positions move by the bones' length changes only.

Shapes: joints (T, 22, 3) metres, Y up, HumanML3D order; rotations (T, 22, 3, 3), row 0 the root's global rotation,
row j the rotation of joint j in its parent's frame (it turns the offsets of j's children).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import CANONICAL_OFFSETS, NUM_JOINTS, PARENTS, RAW_OFFSETS

BRANCHES: dict[int, tuple[int, int, int]] = {0: (1, 2, 3), 9: (13, 14, 12)}
"""Branching joint → (left child, right child, up child)."""


def children() -> list[list[int]]:
    """Child joints of every joint."""
    kids: list[list[int]] = [[] for _ in range(NUM_JOINTS)]
    for j, p in enumerate(PARENTS):
        if p >= 0:
            kids[p].append(j)
    return kids


def _unit(v: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(norm, 1e-12)


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Shortest rotations (..., 3, 3) taking directions ``a`` onto ``b`` (antiparallel: 180° about a normal)."""
    a, b = _unit(a), _unit(b)
    a = np.broadcast_to(a, b.shape)
    axis = np.cross(a, b)
    sin = np.linalg.norm(axis, axis=-1)
    cos = np.sum(a * b, axis=-1)
    helper = np.where(np.abs(a[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    perp = _unit(np.cross(a, helper))
    flip = sin < 1e-9
    axis = np.where(flip[..., None], perp, axis / np.maximum(sin, 1e-12)[..., None])
    angle = np.arctan2(sin, cos)
    angle = np.where(flip & (cos > 0), 0.0, angle)
    x, y, z = axis[..., 0], axis[..., 1], axis[..., 2]
    zero = np.zeros_like(x)
    k = np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], -2)
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def kabsch(rest: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Rotations (T, 3, 3) minimising Σ_k |R rest_k − current_tk|²; ``rest`` (K, 3), ``current`` (T, K, 3)."""
    h = np.einsum("tki,kj->tij", current, rest)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(u @ vt))
    fix = np.ones(u.shape[:-2] + (3,))
    fix[..., 2] = np.where(d == 0, 1.0, d)
    return (u * fix[..., None, :]) @ vt


def _branch_frame(left: np.ndarray, right: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(T, 3, 3) frames (columns x, y, z): x from the right to the left child, y towards ``up``."""
    x = _unit(left - right)
    y = _unit(up - np.sum(up * x, axis=-1, keepdims=True) * x)
    return np.stack([x, y, np.cross(x, y)], axis=-1)


def rest_offsets(joints: np.ndarray) -> np.ndarray:
    """(22, 3) rest offsets in metres of a motion's own skeleton (row 0 zero): each bone along its HumanML3D
    ``RAW_OFFSETS`` direction with the motion's mean length; the two branching joints keep the mean shape of
    their child triangle as measured in the motion."""
    joints = np.asarray(joints, dtype=np.float64)
    parents = np.asarray(PARENTS)
    offsets = np.zeros((NUM_JOINTS, 3))
    lengths = np.linalg.norm(joints[:, 1:] - joints[:, parents[1:]], axis=-1).mean(axis=0)
    offsets[1:] = RAW_OFFSETS[1:] * lengths[:, None]
    for joint, (left, right, up) in BRANCHES.items():
        rel = joints[:, [left, right, up]] - joints[:, joint, None]
        frame = _branch_frame(rel[:, 0], rel[:, 1], rel[:, 2])
        offsets[[left, right, up]] = np.einsum("tij,tki->tkj", frame, rel).mean(axis=0)
    return offsets


def solve_rotations(joints: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Local rotations (T, 22, 3, 3) that pose the skeleton ``offsets`` (22, 3) like ``joints`` (T, 22, 3)."""
    joints = np.asarray(joints, dtype=np.float64)
    n = joints.shape[0]
    kids = children()
    global_rot = np.empty((n, NUM_JOINTS, 3, 3))
    local_rot = np.empty((n, NUM_JOINTS, 3, 3))
    placed = np.empty_like(joints)
    placed[:, 0] = joints[:, 0]
    for j in range(NUM_JOINTS):
        parent = PARENTS[j]
        parent_rot = global_rot[:, parent] if parent >= 0 else np.broadcast_to(np.eye(3), (n, 3, 3))
        if parent >= 0:
            placed[:, j] = placed[:, parent] + parent_rot @ offsets[j]
        if j in BRANCHES:
            kids_j = list(BRANCHES[j])
            rot = kabsch(offsets[kids_j], joints[:, kids_j] - placed[:, j, None])
            global_rot[:, j] = rot
            local_rot[:, j] = np.swapaxes(parent_rot, -1, -2) @ rot
        elif kids[j]:
            (child,) = kids[j]
            target = joints[:, child] - placed[:, j]
            local = rotation_between(offsets[child], np.einsum("tji,tj->ti", parent_rot, target))
            local[np.linalg.norm(target, axis=-1) < 1e-9] = np.eye(3)
            local_rot[:, j] = local
            global_rot[:, j] = parent_rot @ local
        else:
            local_rot[:, j] = np.eye(3)
            global_rot[:, j] = parent_rot
    return local_rot


def global_rotations(local: np.ndarray) -> np.ndarray:
    """Global rotations (T, 22, 3, 3) from local ones."""
    out = np.empty_like(local)
    for j in range(NUM_JOINTS):
        parent = PARENTS[j]
        out[:, j] = local[:, j] if parent < 0 else out[:, parent] @ local[:, j]
    return out


def forward_kinematics(local: np.ndarray, root: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Joint positions (T, 22, 3) of local rotations (T, 22, 3, 3), root positions (T, 3) and offsets (22, 3)."""
    glob = global_rotations(np.asarray(local, dtype=np.float64))
    joints = np.empty(glob.shape[:2] + (3,))
    joints[:, 0] = root
    for j in range(1, NUM_JOINTS):
        parent = PARENTS[j]
        joints[:, j] = joints[:, parent] + glob[:, parent] @ offsets[j]
    return joints


@dataclass(frozen=True)
class RigidMotion:
    """A motion as rotations on one fixed skeleton.

    Attributes:
        local: (T, 22, 3, 3) local rotations (row 0 the root's global rotation).
        root: (T, 3) pelvis positions in metres.
        offsets: (22, 3) rest offsets in metres of each joint from its parent.
    """

    local: np.ndarray
    root: np.ndarray
    offsets: np.ndarray

    @property
    def joints(self) -> np.ndarray:
        """(T, 22, 3) float32 positions: the forward kinematics."""
        return forward_kinematics(self.local, self.root, self.offsets).astype(np.float32)


def fit(joints: np.ndarray, offsets: np.ndarray | None = CANONICAL_OFFSETS) -> RigidMotion:
    """Rotations on a fixed skeleton that follow ``joints`` (T, 22, 3).

    Args:
        joints: positions in metres; finite, T ≥ 1.
        offsets: (22, 3) skeleton; default HumanML3D's canonical one; None: the motion's own mean skeleton
            (:func:`rest_offsets`).
    Raises:
        SimdiffError: another shape, or non-finite values.
    """
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (NUM_JOINTS, 3) or joints.shape[0] < 1:
        raise SimdiffError(f"a rigid fit needs (T, 22, 3) joints with T >= 1, got {joints.shape}")
    if not np.all(np.isfinite(joints)):
        raise SimdiffError("a rigid fit needs finite joints; these contain NaN or infinite values")
    offsets = rest_offsets(joints) if offsets is None else np.asarray(offsets, dtype=np.float64)
    return RigidMotion(solve_rotations(joints, offsets), joints[:, 0].copy(), offsets)


def rigidify(joints: np.ndarray, offsets: np.ndarray | None = CANONICAL_OFFSETS) -> np.ndarray:
    """``fit(joints, offsets).joints``: the same motion with constant bone lengths, float32 (T, 22, 3)."""
    return fit(joints, offsets).joints


def bone_lengths(joints: np.ndarray) -> np.ndarray:
    """(T, 21) length in metres of the bone from each joint's parent to joints 1..21."""
    joints = np.asarray(joints, dtype=np.float64)
    parents = np.asarray(PARENTS)
    return np.linalg.norm(joints[..., 1:, :] - joints[..., parents[1:], :], axis=-1)


SMOOTH_ROOT_FRAMES: float = 1.5
"""Gaussian σ in frames of the root path's smoothing in :func:`joints_from_features`."""
SMOOTH_POSE_FRAMES: float = 1.0
"""Gaussian σ in frames of the root-relative pose's smoothing. With these two, the largest joint speed of 96
generated motions (walk, run, jump, floor prompts) fell from a median 14–21 m/s (one-frame leg swaps; corpus
maximum 15.6 walks, 11.3 runs) to 6–10, and runs' 99th-percentile root acceleration from 75 to 11 m/s² (corpus
17), moving joints by 10–33 mm on average."""


def gaussian_filter_frames(x: np.ndarray, sigma: float) -> np.ndarray:
    """``scipy.ndimage.gaussian_filter1d(x, sigma, axis=0, mode="nearest")`` (radius 4σ) for float64 (T, ...) arrays.

    Its own 6 lines because importing ``scipy.ndimage`` costs 0.3 s of a 2.8 s cold ``simdiff generate``."""
    radius = int(4.0 * sigma + 0.5)
    weights = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    weights /= weights.sum()
    padded = np.concatenate([np.repeat(x[:1], radius, 0), x, np.repeat(x[-1:], radius, 0)])
    return sum(w * padded[i : i + len(x)] for i, w in enumerate(weights))


def smooth_positions(joints: np.ndarray) -> np.ndarray:
    """(T, 22, 3) positions with the root path and the root-relative pose low-passed (Gaussian,
    :data:`SMOOTH_ROOT_FRAMES` and :data:`SMOOTH_POSE_FRAMES`; the ends held), float64."""
    joints = np.asarray(joints, dtype=np.float64)
    root = joints[:, :1]
    return gaussian_filter_frames(joints - root, SMOOTH_POSE_FRAMES) + gaussian_filter_frames(root, SMOOTH_ROOT_FRAMES)


def joints_from_features(features: np.ndarray, foot_lock: float = 0.0) -> np.ndarray:
    """The joints every command writes for (T, 263) un-normalised features: their positions
    (:func:`simdiff.motion.features.features_to_joints`) smoothed (:func:`smooth_positions`; the network's
    one-frame glitches), fitted with rotations on the motion's own fixed skeleton, then, when ``foot_lock`` > 0,
    the feet the contact channels mark as planted held in place at that strength by leg IK
    (:func:`simdiff.motion.contact_hold.hold_contacts`); float32 (T, 22, 3), bone lengths constant."""
    from simdiff.motion.contact_hold import hold_contacts
    from simdiff.motion.features import SLICES, features_to_joints

    features = np.asarray(features, dtype=np.float32)
    joints = rigidify(smooth_positions(np.asarray(features_to_joints(features))), None)
    if not foot_lock:
        return joints
    return hold_contacts(joints, features[:, SLICES["contacts"]], foot_lock)


def decode_inputs(foot_lock: float) -> dict[str, object]:
    """What :func:`joints_from_features` depends on besides the features (the foot cleanup's version when
    ``foot_lock`` > 0, the smoothing, the hold's release), for the fingerprints of cached measurements."""
    from simdiff.motion.contact_hold import RELEASE_FRAMES
    from simdiff.motion.foot_lock import CLEANUP_VERSION

    out: dict[str, object] = {"foot_cleanup": CLEANUP_VERSION} if foot_lock else {}
    out["joints"] = {"smooth": [SMOOTH_ROOT_FRAMES, SMOOTH_POSE_FRAMES], "rigid": True, "release": RELEASE_FRAMES}
    return out


def batch_joints_from_features(features: object, lengths: object, foot_lock: float = 0.0) -> np.ndarray:
    """:func:`joints_from_features` of a (B, T, 263) batch (numpy or torch) with (B,) valid frames: float32
    (B, T, 22, 3); frames past a clip's length repeat its last valid frame."""
    feats = np.asarray(features.detach().cpu() if hasattr(features, "detach") else features, dtype=np.float32)
    lens = np.asarray(lengths.cpu() if hasattr(lengths, "cpu") else lengths, dtype=np.int64).reshape(-1)
    out = np.empty(feats.shape[:2] + (NUM_JOINTS, 3), dtype=np.float32)
    for i, (f, n) in enumerate(zip(feats, lens)):
        n = int(min(max(n, 1), f.shape[0]))
        out[i, :n] = joints_from_features(f[:n], foot_lock)
        out[i, n:] = out[i, n - 1]
    return out
