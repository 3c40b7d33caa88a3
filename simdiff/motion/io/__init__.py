"""Motion file I/O: readers (ASF/AMC, BVH, DeepMimic, .npy), retargeting to the
HumanML3D 22-joint skeleton, and writers (BVH, .npy).

:func:`load_joints` reads any supported file into (T, 22, 3) float32 joint positions in
metres, Y-up, at 20 fps.

Sources and what the readers do for them (rig families: :mod:`simdiff.motion.io.rigs`):

- CMU ASF/AMC and HDM05 ASF/AMC (``HDM_<actor>.asf`` found beside ``HDM_<actor>_*.amc``;
  rate from ``CMU_data.csv`` or a ``_120`` name suffix, else 120 fps);
- BVH (rate: a folder ``readme.txt`` rate, e.g. acLSTM salsa 60 fps, else the header;
  start-up frames dropped: the family's T-pose, then any T-pose / blend-out transient,
  counted in ``meta["dropped_frames"]``): CMU Character-Creator, CMU Motionbuilder and the
  ASF-named CMU BVH (CMU ASF units; the dropped thorax bone is put back; floor tilt
  levelled), Daz-style CMU/acLSTM (cm; floor tilt levelled), Bandai-Namco (cm, 30 fps),
  generic bipeds;
- DeepMimic JSON (``.txt``): variable frame durations are resampled on their time stamps;
  :func:`retarget_rig` applies the DeepMimic ground clean-up ``lift_penetrations``;
- ``.npy`` HumanML3D joints or features.

Per-family clean-ups (``prepare`` before mapping, ``finish`` after retargeting) run inside
:func:`retarget_rig` / :func:`load_joints` and are switched off with ``clean=False``.

BVH units (file unit -> metres), in order: the ``units`` argument ("m", "cm", "mm",
"inch", "cmu" or a factor); the rig family's known unit (Bandai, Daz: cm; Motionbuilder:
inch / 0.45); else the unit among those that brings the body size (90th percentile over
frames of the largest joint-cloud extent) nearest 1.7 m.

``simdiff.motion.io.retarget`` and ``simdiff.motion.io.resample`` are always the modules;
the functions are :func:`retarget_rig` (also exported here) and
``simdiff.motion.io.resample.resample``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.motion.io.asf_amc import DEFAULT_FPS as AMC_DEFAULT_FPS
from simdiff.motion.io.asf_amc import (
    AsfSkeleton,
    amc_fps_from_name,
    find_asf,
    lookup_cmu_fps,
    read_amc,
    read_asf,
)
from simdiff.motion.io.bvh import (
    KNOWN_SCALES,
    leading_transient,
    parse_bvh,
    read_bvh,
    rig_from_bvh,
    starts_with_tpose,
)
from simdiff.motion.io.bvh_writer import write_bvh
from simdiff.motion.io.gltf_writer import write_glb
from simdiff.motion.io.deepmimic import read_deepmimic
from simdiff.motion.io.npy import check_coordinates, read_npy, save_npy
from simdiff.motion.io.rates import check_fps, folder_fps_hint
from simdiff.motion.io.resample import resample as _resample
from simdiff.motion.io.retarget import retarget_rig, to_canonical_lengths
from simdiff.motion.io.rigs import RigSpec, detect_rig
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.skeleton import FPS

__all__ = [
    "AsfSkeleton",
    "RigMotion",
    "check_regular_file",
    "detect_rig",
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
    "write_glb",
]

SUFFIXES: tuple[str, ...] = (".amc", ".bvh", ".txt", ".json", ".npy")
"""File types :func:`load_joints` understands."""


def load_rig(
    path: str | Path,
    *,
    asf: str | Path | None = None,
    fps: float | None = None,
    drop_first: bool | None = None,
    units: str | float | None = None,
) -> RigMotion:
    """Read a motion file on its own rig (no retargeting, no resampling).

    Args:
        path: ``.amc``, ``.bvh`` or DeepMimic ``.txt``/``.json``.
        asf: skeleton of an ``.amc`` (default: :func:`find_asf`: ``SS.asf`` or
            ``HDM_<actor>.asf`` beside it or in an ``asf/`` folder).
        fps: the file's frame rate, overriding the file's own (AMC default: from a
            ``CMU_data.csv`` beside the data, a ``_120`` name suffix, else 120; BVH default:
            a folder rate in a ``readme.txt`` one level up
            (:func:`~simdiff.motion.io.rates.folder_fps_hint`), else the header).
        drop_first: BVH only: True skips frame 0, False keeps every frame; None drops it
            when the rig family always starts with a T-pose (CMU Motionbuilder), then any
            detected start-up transient (:func:`~simdiff.motion.io.bvh.leading_transient`:
            an added T-pose and the blend out of it). ``meta["dropped_frames"]`` counts them.
        units: BVH only: file unit ("m", "cm", "mm", "inch", "cmu" or metres per unit);
            None: the rig family's unit, else detected from the body size.
    Returns:
        RigMotion; ``meta["rig"]`` is the detected :class:`~simdiff.motion.io.rigs.RigSpec`
        for BVH files.
    Raises:
        MotionFormatError: unknown extension, missing ASF, or a malformed file.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    fps = check_fps(fps, "fps") if fps is not None else None
    check_regular_file(path)
    if units is not None and suffix != ".bvh":
        raise MotionFormatError(path, f"a unit ({units!r}) applies to BVH files only")
    if suffix == ".amc":
        skeleton = Path(asf) if asf is not None else find_asf(path)
        if skeleton is None:
            raise MotionFormatError(
                path, "no ASF skeleton found (looked for SS.asf / HDM_<actor>.asf beside it and in asf/); pass --asf FILE"
            )
        rate = fps if fps is not None else (
            lookup_cmu_fps(path) or amc_fps_from_name(path) or AMC_DEFAULT_FPS
        )
        return read_amc(path, skeleton, fps=rate)
    if suffix == ".bvh":
        return _load_bvh(path, fps=fps, drop_first=drop_first, units=units)
    if suffix in (".txt", ".json"):
        return read_deepmimic(path, fps=fps)
    raise MotionFormatError(path, f"unsupported motion file type {suffix!r} (known: {', '.join(SUFFIXES)})")


def check_regular_file(path: Path) -> None:
    """Refuse a ``path`` that is missing, a folder, or not a regular file (a device such as ``/dev/zero``, a pipe).

    Raises:
        MotionFormatError: one line naming the file and what it is.
    """
    if path.is_file():
        return
    if path.is_dir():
        raise MotionFormatError(path, "a folder, not a motion file")
    if path.exists():
        raise MotionFormatError(path, "not a regular file (a device, pipe or socket), not a motion file")
    raise MotionFormatError(path, "no such file")


def _units_to_scale(path: Path, units: str | float) -> float:
    """Metres per file unit of a ``units`` argument."""
    if isinstance(units, str):
        if units.lower() not in KNOWN_SCALES:
            raise MotionFormatError(path, f"unknown units {units!r} (known: {', '.join(KNOWN_SCALES)})")
        return KNOWN_SCALES[units.lower()]
    if not 0 < float(units) < math.inf:
        raise MotionFormatError(path, f"a unit must be a positive finite number of metres, got {units!r}")
    return float(units)


def _load_bvh(path: Path, *, fps: float | None, drop_first: bool | None,
              units: str | float | None) -> RigMotion:
    """A BVH on its rig: family detected from the joint names, its units, sites and T-pose."""
    bvh = parse_bvh(path)
    try:
        spec: RigSpec | None = detect_rig(tuple(j.name for j in bvh.joints), path)
    except MotionFormatError:  # an unknown rig can still be read (not retargeted)
        spec = None
    scale = _units_to_scale(path, units) if units is not None else (spec.units if spec else None)
    drop = (spec is not None and spec.first_frame_tpose) if drop_first is None else drop_first
    hint = folder_fps_hint(path) if fps is None else None
    rig = rig_from_bvh(bvh, scale=scale, fps=fps if fps is not None else hint, drop_first=drop,
                       sites=spec.bvh_sites if spec else (),
                       rest_axes=spec.rest_axes if spec else ((1, 0, 0), (0, 1, 0), (0, 0, 1)))
    dropped = int(drop)
    if drop_first is None:
        skip = max(leading_transient(rig.positions, rig.fps), int(starts_with_tpose(rig.positions)))
        if skip:
            rig = RigMotion(rig.names, rig.parents, rig.positions[skip:], rig.fps, rig.source, rig.meta)
            dropped += skip
    rig.meta["dropped_frames"] = dropped
    rig.meta["fps_source"] = "argument" if fps is not None else ("readme" if hint else "header")
    if spec is not None:
        rig.meta["rig"] = spec
    return rig


def load_joints(
    path: str | Path,
    *,
    asf: str | Path | None = None,
    fps: float | None = None,
    drop_first: bool | None = None,
    units: str | float | None = None,
    canonical: bool = False,
    clean: bool = True,
) -> np.ndarray:
    """Read any supported motion file as HumanML3D joints.

    Dispatches on the extension: ``.amc`` (+ ASF), ``.bvh``, DeepMimic ``.txt``/``.json``,
    ``.npy`` joints (T, 22, 3) or un-normalised HumanML3D features (T, 263) (via
    ``simdiff.motion.features.features_to_joints``). Source rigs are retargeted
    (:func:`retarget_rig`), resampled to 20 fps with an anti-alias filter and put on the floor.

    Args:
        path: the motion file.
        asf: ASF skeleton for an ``.amc`` file (default: found beside it).
        fps: the source frame rate, overriding the file's (for ``.npy``: default 20); any rate,
            given or read, must be a finite number in [1, 1000] Hz
            (:func:`~simdiff.motion.io.rates.check_fps`).
        drop_first: BVH only, see :func:`load_rig`.
        units: BVH only, file unit, see :func:`load_rig`.
        canonical: rebuild with HumanML3D's canonical bone lengths.
        clean: apply the rig family's clean-up (DeepMimic: ``lift_penetrations``; CMU
            Motionbuilder: thorax restored), see :func:`retarget_rig`.
    Returns:
        (T, 22, 3) float32 joint positions in metres, Y-up, 20 fps.
    Raises:
        MotionFormatError: one line naming the file (and line) of any bad input, including joints beyond
            ±:data:`~simdiff.limits.MAX_COORD` m (10 km).
        FrameRateError: ``fps`` outside [1, 1000] Hz (a ``SimdiffError``).
    """
    path = Path(path)
    fps = check_fps(fps, "fps") if fps is not None else None
    if path.suffix.lower() == ".npy":
        check_regular_file(path)
        if units is not None:
            raise MotionFormatError(path, f"a unit ({units!r}) applies to BVH files only")
        array = read_npy(path)
        if array.ndim == 2:
            # lazy: the feature pipeline (simdiff.motion.features) is heavier and optional here
            from simdiff.motion.features import features_to_joints

            try:
                array = np.asarray(features_to_joints(array), dtype=np.float32)
            except (ValueError, SimdiffError) as exc:
                raise MotionFormatError(path, f"bad HumanML3D features: {exc}") from None
            if not np.all(np.isfinite(array)):
                raise MotionFormatError(path, "bad HumanML3D features: the joints they give are not finite")
            check_coordinates(path, array, "the joints of these features")
        if fps is not None and fps != FPS:
            array = _resample(array, fps, FPS)
        if canonical:
            array = to_canonical_lengths(array, floor=False)
        return np.ascontiguousarray(array, dtype=np.float32)
    rig = load_rig(path, asf=asf, fps=fps, drop_first=drop_first, units=units)
    joints = retarget_rig(rig, fps=FPS, canonical=canonical, clean=clean)
    check_coordinates(path, joints)
    return joints
