"""Write a :class:`~simdiff.motion.rigid.RigidMotion` as a binary glTF 2.0 file (``.glb``) with a skinned body.

Layout: node j is joint j (HumanML3D order, named after :data:`~simdiff.motion.skeleton.JOINT_NAMES`), its
translation the rest offset from its parent; the pelvis node (the scene's first root) rests at the motion's
first pelvis position on the ground plane with the rest legs standing on y = 0. Rest rotations are the
identity. The last node holds the body mesh (:mod:`simdiff.motion.body_mesh`) and the skin (joints 0..21, inverse
bind matrices = the inverse rest transforms). One animation ("motion") has a rotation channel per joint (unit
quaternions x, y, z, w from the local matrices, sign-continuous over time) and the pelvis translation channel,
LINEAR, key times k / fps seconds. glTF is Y up with the front +Z, like the motion: no axis change.

The file is written by hand (numpy + json): 12-byte header, JSON chunk padded with spaces, BIN chunk padded
with zeros, every buffer view 4-byte aligned.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import write_bytes
from simdiff.motion.rigid import RigidMotion
from simdiff.motion.skeleton import FPS, JOINT_NAMES, NUM_JOINTS, PARENTS

FLOAT, UNSIGNED_BYTE, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5121, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
BODY_COLOUR: tuple[float, float, float, float] = (0.78, 0.55, 0.42, 1.0)
"""Base colour (linear RGBA) of the body material."""


def matrix_to_quaternion(m: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) as x, y, z, w of rotation matrices (..., 3, 3) (largest-component method)."""
    m = np.asarray(m, dtype=np.float64)
    trace = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    cands = np.stack([
        np.stack([1 + m[..., 0, 0] - m[..., 1, 1] - m[..., 2, 2], m[..., 0, 1] + m[..., 1, 0],
                  m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] - m[..., 1, 2]], -1),
        np.stack([m[..., 0, 1] + m[..., 1, 0], 1 - m[..., 0, 0] + m[..., 1, 1] - m[..., 2, 2],
                  m[..., 1, 2] + m[..., 2, 1], m[..., 0, 2] - m[..., 2, 0]], -1),
        np.stack([m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                  1 - m[..., 0, 0] - m[..., 1, 1] + m[..., 2, 2], m[..., 1, 0] - m[..., 0, 1]], -1),
        np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1],
                  1 + trace], -1),
    ], -2)  # (..., 4 candidates, 4); candidate k has its k-th component largest when chosen
    diag = np.stack([m[..., 0, 0], m[..., 1, 1], m[..., 2, 2], trace], -1)
    best = np.argmax(diag, axis=-1)
    q = np.take_along_axis(cands, best[..., None, None], -2)[..., 0, :]
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def continuous(q: np.ndarray) -> np.ndarray:
    """Quaternions (T, ..., 4) with signs flipped so consecutive frames have a non-negative dot product."""
    q = np.array(q, dtype=np.float64)
    if len(q) > 1:
        dots = np.sum(q[1:] * q[:-1], axis=-1)
        flips = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=0)
        q[1:] *= flips[..., None]
    return q


class _Bin:
    """The BIN chunk under construction: 4-byte aligned buffer views and their accessors."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(self, array: np.ndarray, kind: str, component: int, target: int | None = None,
            bounds: bool = False) -> int:
        """Append ``array`` (count, n) as one view + accessor of type ``kind``; returns the accessor index."""
        raw = np.ascontiguousarray(array).tobytes()
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.data += raw + b"\0" * (-len(raw) % 4)
        self.views.append(view)
        accessor = {"bufferView": len(self.views) - 1, "componentType": component, "count": int(len(array)),
                    "type": kind}
        if bounds:
            flat = np.asarray(array).reshape(len(array), -1)
            accessor["min"] = [float(v) for v in flat.min(axis=0)]
            accessor["max"] = [float(v) for v in flat.max(axis=0)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1


def _check(motion: RigidMotion, fps: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    local = np.asarray(motion.local, dtype=np.float64)
    root = np.asarray(motion.root, dtype=np.float64)
    offsets = np.asarray(motion.offsets, dtype=np.float64)
    if local.ndim != 4 or local.shape[1:] != (NUM_JOINTS, 3, 3) or local.shape[0] < 1:
        raise SimdiffError(f"write_glb needs (T, 22, 3, 3) rotations with T >= 1, got {local.shape}")
    if root.shape != (local.shape[0], 3) or offsets.shape != (NUM_JOINTS, 3):
        raise SimdiffError(f"write_glb needs (T, 3) root and (22, 3) offsets, got {root.shape} and {offsets.shape}")
    if not (np.all(np.isfinite(local)) and np.all(np.isfinite(root)) and np.all(np.isfinite(offsets))):
        raise SimdiffError("write_glb: the motion contains NaN or infinite values")
    if not (np.isfinite(fps) and fps > 0):
        raise SimdiffError(f"write_glb: fps must be a positive number, got {fps}")
    return local, root, offsets


def rest_root(offsets: np.ndarray, root: np.ndarray) -> np.ndarray:
    """(3,) rest pelvis position: over the first frame's pelvis, high enough that the rest joints reach y = 0."""
    heights = np.zeros(NUM_JOINTS)
    for j in range(1, NUM_JOINTS):
        heights[j] = heights[PARENTS[j]] + offsets[j, 1]
    return np.array([root[0, 0], -heights.min(), root[0, 2]])


def glb_bytes(motion: RigidMotion, fps: float = FPS, body: bool = True) -> bytes:
    """The ``.glb`` file contents of ``motion`` (see the module notes)."""
    local, root, offsets = _check(motion, fps)
    frames = local.shape[0]
    rest = rest_root(offsets, root)
    kids: list[list[int]] = [[] for _ in range(NUM_JOINTS)]
    for j, p in enumerate(PARENTS):
        if p >= 0:
            kids[p].append(j)
    nodes: list[dict] = []
    for j in range(NUM_JOINTS):
        node: dict = {"name": JOINT_NAMES[j], "translation": [float(v) for v in (rest if j == 0 else offsets[j])]}
        if kids[j]:
            node["children"] = kids[j]
        nodes.append(node)
    buf = _Bin()
    gltf: dict = {"asset": {"version": "2.0", "generator": "simdiff"}, "scene": 0,
                  "scenes": [{"name": "motion", "nodes": [0]}], "nodes": nodes}
    if body:
        from simdiff.motion.body_mesh import build_body, rest_positions

        mesh = build_body(offsets, rest)
        attributes = {
            "POSITION": buf.add(mesh.positions, "VEC3", FLOAT, ARRAY_BUFFER, bounds=True),
            "NORMAL": buf.add(mesh.normals, "VEC3", FLOAT, ARRAY_BUFFER),
            "JOINTS_0": buf.add(mesh.joints.astype(np.uint8), "VEC4", UNSIGNED_BYTE, ARRAY_BUFFER),
            "WEIGHTS_0": buf.add(mesh.weights, "VEC4", FLOAT, ARRAY_BUFFER),
        }
        wide = len(mesh.positions) > 65535
        indices = buf.add(mesh.triangles.reshape(-1).astype(np.uint32 if wide else np.uint16), "SCALAR",
                          UNSIGNED_INT if wide else UNSIGNED_SHORT, ELEMENT_ARRAY_BUFFER)
        ibm = np.tile(np.eye(4), (NUM_JOINTS, 1, 1))
        ibm[:, :3, 3] = -rest_positions(offsets, rest)
        ibm_accessor = buf.add(np.swapaxes(ibm, 1, 2).astype(np.float32).reshape(NUM_JOINTS, 16), "MAT4", FLOAT)
        nodes.append({"name": "body", "mesh": 0, "skin": 0})
        gltf["scenes"][0]["nodes"].append(NUM_JOINTS)
        gltf["meshes"] = [{"name": "body", "primitives": [{"attributes": attributes, "indices": indices,
                                                            "material": 0, "mode": 4}]}]
        gltf["materials"] = [{"name": "body", "pbrMetallicRoughness": {
            "baseColorFactor": list(BODY_COLOUR), "metallicFactor": 0.0, "roughnessFactor": 0.8}}]
        gltf["skins"] = [{"name": "skeleton", "joints": list(range(NUM_JOINTS)), "skeleton": 0,
                          "inverseBindMatrices": ibm_accessor}]
    times = buf.add((np.arange(frames) / float(fps)).astype(np.float32), "SCALAR", FLOAT, bounds=True)
    quats = continuous(matrix_to_quaternion(local)).astype(np.float32)
    samplers, channels = [], []
    for j in range(NUM_JOINTS):
        samplers.append({"input": times, "output": buf.add(quats[:, j], "VEC4", FLOAT), "interpolation": "LINEAR"})
        channels.append({"sampler": j, "target": {"node": j, "path": "rotation"}})
    samplers.append({"input": times, "output": buf.add(root.astype(np.float32), "VEC3", FLOAT),
                     "interpolation": "LINEAR"})
    channels.append({"sampler": NUM_JOINTS, "target": {"node": 0, "path": "translation"}})
    gltf["animations"] = [{"name": "motion", "samplers": samplers, "channels": channels}]
    gltf["accessors"], gltf["bufferViews"] = buf.accessors, buf.views
    gltf["buffers"] = [{"byteLength": len(buf.data)}]
    text = json.dumps(gltf, separators=(",", ":"), allow_nan=False).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary = bytes(buf.data)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return b"".join([struct.pack("<4sII", b"glTF", 2, total), struct.pack("<I4s", len(text), b"JSON"), text,
                     struct.pack("<I4s", len(binary), b"BIN\0"), binary])


def write_glb(path: str | Path, motion: RigidMotion, fps: float = FPS, body: bool = True) -> Path:
    """Write ``motion`` as a binary glTF (skeleton, animation and, with ``body``, a skinned body), atomically.

    Args:
        path: output ``.glb`` file (parent folders are created).
        motion: rotations on a fixed skeleton (:func:`simdiff.motion.rigid.fit`), metres, Y up.
        fps: frame rate in frames per second (HumanML3D: 20).
        body: include the skinned body mesh; False writes the animated skeleton only.
    Returns:
        The path written.
    Raises:
        SimdiffError: one line for a motion that is not 22 joints, has no frame or holds NaN/inf, or a bad fps.
    """
    return write_bytes(Path(path), glb_bytes(motion, fps, body))
