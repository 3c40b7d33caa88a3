"""Motion file I/O: readers (ASF/AMC, BVH, DeepMimic, .npy), retargeting to the
HumanML3D 22-joint skeleton, and writers (BVH, .npy).

:func:`load_joints` reads any supported file into (T, 22, 3) float32 joint positions in
metres, Y-up, at 20 fps.

``simdiff.motion.io.retarget`` and ``simdiff.motion.io.resample`` are always the modules;
the functions are :func:`retarget_rig` (also exported here) and
``simdiff.motion.io.resample.resample``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.motion.io.asf_amc import DEFAULT_FPS as AMC_DEFAULT_FPS
from simdiff.motion.io.asf_amc import AsfSkeleton, find_asf, lookup_cmu_fps, read_amc, read_asf
from simdiff.motion.io.bvh import read_bvh, starts_with_tpose
from simdiff.motion.io.bvh_writer import write_bvh
from simdiff.motion.io.deepmimic import read_deepmimic
from simdiff.motion.io.npy import read_npy, save_npy
from simdiff.motion.io.resample import resample as _resample
from simdiff.motion.io.retarget import retarget_rig, to_canonical_lengths
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.skeleton import FPS

__all__ = [
    "AsfSkeleton",
    "RigMotion",
    "find_asf",
    "load_joints",
    "load_rig",
    "read_amc",
    "read_asf",
    "read_bvh",
    "read_deepmimic",
    "read_npy",
    "retarget_rig",
    "save_npy",
    "to_canonical_lengths",
    "write_bvh",
]

SUFFIXES: tuple[str, ...] = (".amc", ".bvh", ".txt", ".json", ".npy")
"""File types :func:`load_joints` understands."""


def load_rig(
    path: str | Path,
    *,
    asf: str | Path | None = None,
    fps: float | None = None,
    drop_first: bool | None = None,
) -> RigMotion:
    """Read a motion file on its own rig (no retargeting, no resampling).

    Args:
        path: ``.amc``, ``.bvh`` or DeepMimic ``.txt``/``.json``.
        asf: skeleton of an ``.amc`` (default: ``SS.asf`` beside it or in a sibling ``asf/``).
        fps: the file's frame rate when it cannot be read from it (AMC: default from a
            ``CMU_data.csv`` beside the data, else 120); overrides the file's own rate.
        drop_first: BVH only: skip frame 0; None drops it when it is an added T-pose.
    Raises:
        MotionFormatError: unknown extension, missing ASF, or a malformed file.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if not path.is_file():
        raise MotionFormatError(path, "no such file")
    if suffix == ".amc":
        skeleton = Path(asf) if asf is not None else find_asf(path)
        if skeleton is None:
            raise MotionFormatError(
                path, "no ASF skeleton found (looked for SS.asf beside it and in ../asf/); pass asf="
            )
        rate = fps if fps is not None else (lookup_cmu_fps(path) or AMC_DEFAULT_FPS)
        return read_amc(path, skeleton, fps=rate)
    if suffix == ".bvh":
        rig = read_bvh(path, fps=fps, drop_first=bool(drop_first))
        if drop_first is None and starts_with_tpose(rig.positions):
            rig = RigMotion(rig.names, rig.parents, rig.positions[1:], rig.fps, rig.source, rig.meta)
        return rig
    if suffix in (".txt", ".json"):
        return read_deepmimic(path, fps=fps)
    raise MotionFormatError(path, f"unsupported motion file type {suffix!r} (known: {', '.join(SUFFIXES)})")


def load_joints(
    path: str | Path,
    *,
    asf: str | Path | None = None,
    fps: float | None = None,
    drop_first: bool | None = None,
    canonical: bool = False,
) -> np.ndarray:
    """Read any supported motion file as HumanML3D joints.

    Dispatches on the extension: ``.amc`` (+ ASF), ``.bvh``, DeepMimic ``.txt``/``.json``,
    ``.npy`` joints (T, 22, 3) or un-normalised HumanML3D features (T, 263) (via
    ``simdiff.motion.features.features_to_joints``). Source rigs are retargeted
    (:func:`retarget_rig`), resampled to 20 fps with an anti-alias filter and put on the floor.

    Args:
        path: the motion file.
        asf: ASF skeleton for an ``.amc`` file (default: found beside it).
        fps: the source frame rate, overriding the file's (for ``.npy``: default 20).
        drop_first: BVH only, see :func:`load_rig`.
        canonical: rebuild with HumanML3D's canonical bone lengths.
    Returns:
        (T, 22, 3) float32 joint positions in metres, Y-up, 20 fps.
    Raises:
        MotionFormatError: one line naming the file (and line) of any bad input.
    """
    path = Path(path)
    if path.suffix.lower() == ".npy":
        if not path.is_file():
            raise MotionFormatError(path, "no such file")
        array = read_npy(path)
        if array.ndim == 2:
            # lazy: the feature pipeline (simdiff.motion.features) is heavier and optional here
            from simdiff.motion.features import features_to_joints

            try:
                array = np.asarray(features_to_joints(array), dtype=np.float32)
            except (ValueError, SimdiffError) as exc:
                raise MotionFormatError(path, f"bad HumanML3D features: {exc}") from None
        if fps is not None and fps != FPS:
            array = _resample(array, fps, FPS)
        if canonical:
            array = to_canonical_lengths(array, floor=False)
        return np.ascontiguousarray(array, dtype=np.float32)
    rig = load_rig(path, asf=asf, fps=fps, drop_first=drop_first)
    return retarget_rig(rig, fps=FPS, canonical=canonical)
