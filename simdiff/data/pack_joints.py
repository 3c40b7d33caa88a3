"""Clip encoding of training packs (:mod:`simdiff.data.pack`): joints in, features rebuilt on unpack.

A corpus clip's features are ``process_joints`` of its window; the canonical joints those
features describe ((T+1, 22, 3): ``features_to_joints`` plus ``extend_last_frame``) give the
same features back through ``process_joints(..., uniform_skeleton=False, canonical=False)``
(they already have the canonical bones, floor, origin and facing). A pack stores them as

* the root (joint 0) in float32 metres, (N, 3);
* joints 1..21 relative to the root as int16 in steps of :data:`REL_STEP` (1/16384 m,
  ±0.03 mm rounding, range ±2 m), delta-coded along the concatenated frames (wrapping int16
  arithmetic, exact) so that deflate compresses it;
* the four foot-contact channels of every clip as bits: a foot displacement within
  rounding of ``FEET_THRESHOLD`` would otherwise flip a contact.

A mirror ``M<id>`` is not stored: :func:`rebuild_mirror` mirrors ``<id>``'s joints
(``simdiff.motion.mirror.mirror_joints``, as the corpus builders do) and retargets them to the
canonical skeleton as ``process_joints`` does, with the root scale of the builder's mirror
(HumanML3D scales the root by a leg-length ratio of the source body, which the canonical
joints do not carry), measured at pack time by :func:`mirror_scale`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from simdiff.errors import SimdiffError

REL_STEP: float = 2.0**-14
"""Quantisation step (m) of the root-relative joint positions."""
REL_LIMIT: float = 32767 * REL_STEP
"""Largest root-relative coordinate (m) the int16 code holds (~2 m)."""
TOLERANCE: float = 0.1
"""A clip is stored as joints (a mirror as a root scale) only if every feature rebuilt at pack
time (contacts aside, which are stored) is within this many standard deviations
(``Std.npy``) of the corpus's; otherwise its features are stored as they are (float32)."""
CONTACTS = slice(259, 263)


def canonical_joints(features: np.ndarray) -> np.ndarray:
    """(T, 263) features → the (T+1, 22, 3) float64 canonical joints (metres) they describe."""
    from simdiff.motion.features import extend_last_frame, features_to_joints

    f = np.asarray(features, dtype=np.float32)
    return extend_last_frame(np.asarray(features_to_joints(f)), f).astype(np.float64)


def quantize(joints: np.ndarray, clip: str = "") -> tuple[np.ndarray, np.ndarray]:
    """(N, 22, 3) metres → root (N, 3) float32 and root-relative (N, 21, 3) int16 codes.

    Raises:
        SimdiffError: a joint farther than :data:`REL_LIMIT` from the root.
    """
    root = np.asarray(joints[:, 0], dtype=np.float32)
    rel = np.asarray(joints[:, 1:], dtype=np.float64) - root[:, None].astype(np.float64)
    far = float(np.abs(rel).max(initial=0.0))
    if far > REL_LIMIT:
        raise SimdiffError(f"clip {clip}: a joint {far:.2f} m from the root, over the {REL_LIMIT:.2f} m a pack holds")
    return root, np.round(rel / REL_STEP).astype(np.int16)


def dequantize(root: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """Inverse of :func:`quantize`: (N, 22, 3) float64 metres."""
    root64 = np.asarray(root, dtype=np.float64)
    return np.concatenate([root64[:, None], root64[:, None] + rel.astype(np.float64) * REL_STEP], axis=1)


def delta_encode(codes: np.ndarray) -> np.ndarray:
    """Frame-to-frame differences of int16 codes (N, ...) along axis 0, wrapping (exact)."""
    out = codes.copy()
    out[1:] = codes[1:] - codes[:-1]
    return out


def delta_decode(deltas: np.ndarray) -> np.ndarray:
    """Inverse of :func:`delta_encode` (wrapping int16 cumulative sum)."""
    return np.cumsum(deltas, axis=0, dtype=np.int16)


def unpack_contacts(bits: np.ndarray, offset: int, rows: int) -> np.ndarray:
    """(rows, 4) float32 0/1 contacts of the clip whose first contact row is ``offset``."""
    flat = np.unpackbits(bits, count=(offset + rows) * 4)[offset * 4:]
    return flat.reshape(rows, 4).astype(np.float32)


def rebuild_features(joints: np.ndarray) -> np.ndarray:
    """(T+1, 22, 3) canonical joints → (T, 263) float32 features (corpus processing, no retarget)."""
    from simdiff.motion.features import process_joints

    return process_joints(joints, uniform_skeleton=False, canonical=False).features


def _mirrored_retarget(joints: np.ndarray, scale: float) -> np.ndarray:
    """Mirror canonical joints, retarget to the canonical bones with root scale ``scale`` and
    canonicalise (floor, origin, facing +Z), as ``process_joints`` does for the builder's mirror."""
    from simdiff.motion.features import canonicalize
    from simdiff.motion.kinematics import forward_kinematics, inverse_kinematics
    from simdiff.motion.mirror import mirror_joints
    from simdiff.motion.skeleton import CANONICAL_OFFSETS

    mirrored = mirror_joints(np.asarray(joints, dtype=np.float64))
    quats = inverse_kinematics(mirrored, smooth_forward=False, hip_quirk=True)
    return canonicalize(forward_kinematics(quats, mirrored[:, 0] * scale, CANONICAL_OFFSETS))


def rebuild_mirror(joints: np.ndarray, scale: float) -> np.ndarray:
    """(T, 263) float32 features of the mirror of (T+1, 22, 3) canonical joints (see module doc)."""
    return rebuild_features(_mirrored_retarget(joints, scale))


def rebuild_error(rebuilt: np.ndarray, features: np.ndarray, std: np.ndarray) -> float:
    """Largest |rebuilt - features| / std over every channel but the contacts (inf if not finite)."""
    diff = np.abs(np.asarray(rebuilt, dtype=np.float64) - features) / np.asarray(std, dtype=np.float64)
    diff[:, CONTACTS] = 0.0
    error = float(diff.max(initial=0.0))
    return error if np.isfinite(error) else float("inf")


def checked(rebuild: Callable[[], np.ndarray], features: np.ndarray, std: np.ndarray) -> float:
    """:func:`rebuild_error` of ``rebuild()``; inf when it fails (degenerate IK on a frame)."""
    try:
        with np.errstate(invalid="ignore", divide="ignore"):
            rebuilt = rebuild()
    except SimdiffError:
        return float("inf")
    if rebuilt.shape != features.shape:
        return float("inf")
    return rebuild_error(rebuilt, features, std)


def mirror_scale(joints: np.ndarray, mirror_features: np.ndarray, std: np.ndarray) -> tuple[float, float]:
    """Root scale that turns the mirror of ``joints`` into the clip of ``mirror_features``.

    Least squares over the root's displacements from frame 0 (the retarget scales the root
    trajectory and nothing else). Returns ``(scale, error)``: the largest difference between
    the rebuilt mirror's features and ``mirror_features`` in units of ``std`` (contacts aside).
    """
    from simdiff.motion.mirror import mirror_joints

    target = canonical_joints(mirror_features)
    mirrored = mirror_joints(np.asarray(joints, dtype=np.float64))
    if target.shape != mirrored.shape:
        return 1.0, float("inf")
    a = (mirrored[:, 0] - mirrored[:1, 0]).ravel()
    b = (target[:, 0] - target[:1, 0]).ravel()
    scale = float(a @ b / (a @ a)) if a @ a > 1e-12 else 1.0
    if not np.isfinite(scale) or not 0.5 < scale < 2.0:
        return 1.0, float("inf")
    return scale, checked(lambda: rebuild_mirror(joints, scale), mirror_features, std)
