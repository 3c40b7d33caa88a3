"""``simdiff serve``'s skinned body: every motion answer names a ``.glb`` whose node animation reproduces the
joints the answer carries; the vendored three.js files are served from an allow-list and ship in the wheel."""

from __future__ import annotations

import json
import struct
import tomllib
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.motion import synthetic
from simdiff.motion.skeleton import JOINT_NAMES, NUM_JOINTS, PARENTS
from simdiff.serve import ListedMotion, MotionService, ViewerServer
from simdiff.serve.service import MAX_BODIES
from simdiff.serve.testing import write_tiny_model
from simdiff.serve.wire import static_files
from simdiff.train.testing import HashTextEncoder

ROOT = Path(__file__).resolve().parents[1]
STATIC = ROOT / "simdiff" / "serve" / "static"
VENDOR = STATIC / "vendor" / "three"
MESH_BYTES = 400_000
"""Upper bound on the body's frame-independent part (mesh, skin, node tree) in bytes."""
FRAME_BYTES = 22 * 16 + 12 + 4
"""Bytes per frame of animation: a quaternion per joint, the root translation, the key time."""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    model = write_tiny_model(tmp_path_factory.mktemp("tiny_model"))
    walk = ListedMotion("walk.npy", Path("walk.npy"), synthetic.walk(50, turn_rate=0.3))
    srv = ViewerServer(MotionService(model, files=[walk], text_encoder=HashTextEncoder(), steps=4), "127.0.0.1", 0)
    srv.start_in_thread()
    yield srv
    srv.shutdown()
    srv.server_close()
    torch.set_num_threads(threads)


def fetch(server: ViewerServer, path: str, body: dict | None = None, method: str | None = None) -> tuple[int, bytes, str]:
    data = None if body is None else json.dumps(body).encode()
    headers = {} if body is None else {"Content-Type": "application/json"}
    request = urllib.request.Request(server.url + path.lstrip("/"), data=data, headers=headers, method=method)
    try:
        with urllib.request.urlopen(request, timeout=120) as response:
            return response.status, response.read(), response.headers["Content-Type"]
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read(), exc.headers["Content-Type"]


def read_glb(data: bytes) -> tuple[dict, bytes]:
    """(glTF JSON, BIN chunk) of a .glb file, checking its framing."""
    magic, version, total = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, total) == (b"glTF", 2, len(data))
    json_length, json_kind = struct.unpack_from("<I4s", data, 12)
    assert json_kind == b"JSON" and json_length % 4 == 0
    gltf = json.loads(data[20:20 + json_length])
    bin_length, bin_kind = struct.unpack_from("<I4s", data, 20 + json_length)
    assert bin_kind == b"BIN\0" and 28 + json_length + bin_length == len(data)
    return gltf, data[28 + json_length:]


def accessor(gltf: dict, binary: bytes, index: int) -> np.ndarray:
    acc = gltf["accessors"][index]
    view = gltf["bufferViews"][acc["bufferView"]]
    dtype = {5126: np.float32, 5123: np.uint16, 5125: np.uint32, 5121: np.uint8}[acc["componentType"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[acc["type"]]
    values = np.frombuffer(binary, dtype, acc["count"] * width, view["byteOffset"] + acc.get("byteOffset", 0))
    return values.reshape(acc["count"], width).astype(np.float64)


def quaternion_matrices(q: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations of unit quaternions (..., 4) stored x, y, z, w."""
    x, y, z, w = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def animated_joints(data: bytes) -> tuple[np.ndarray, np.ndarray, dict]:
    """(key times, joint positions (T, 22, 3) from the node tree and its animation at every key, glTF JSON)."""
    gltf, binary = read_glb(data)
    nodes = gltf["nodes"]
    parent = {child: i for i, node in enumerate(nodes) for child in node.get("children", [])}
    (animation,) = gltf["animations"]
    rotations: dict[int, np.ndarray] = {}
    translations: dict[int, np.ndarray] = {}
    times = None
    for channel in animation["channels"]:
        sampler = animation["samplers"][channel["sampler"]]
        times = accessor(gltf, binary, sampler["input"])[:, 0]
        values = accessor(gltf, binary, sampler["output"])
        target = channel["target"]
        (rotations if target["path"] == "rotation" else translations)[target["node"]] = values
    frames = len(times)
    world_rot = np.zeros((len(nodes), frames, 3, 3))
    world_pos = np.zeros((len(nodes), frames, 3))
    for i, node in enumerate(nodes):  # parents come first in this file
        local_rot = quaternion_matrices(rotations[i]) if i in rotations else np.broadcast_to(np.eye(3), (frames, 3, 3))
        local_pos = translations.get(i, np.broadcast_to(np.asarray(node.get("translation", [0, 0, 0]), float), (frames, 3)))
        if i in parent:
            assert parent[i] < i
            world_pos[i] = world_pos[parent[i]] + np.einsum("tij,tj->ti", world_rot[parent[i]], local_pos)
            world_rot[i] = world_rot[parent[i]] @ local_rot
        else:
            world_pos[i], world_rot[i] = local_pos, local_rot
    joints = [next(i for i, n in enumerate(nodes) if n.get("name") == name) for name in JOINT_NAMES]
    return times, np.swapaxes(world_pos[joints], 0, 1), gltf


def test_generated_body_reproduces_the_answer_joints(server):
    status, raw, _ = fetch(server, "/api/generate", {"text": "a person jumps forward", "seconds": 2.5, "seed": 3})
    assert status == 200, raw
    answer = json.loads(raw)
    joints = np.asarray(answer["joints"])
    assert answer["body"].startswith("/api/body/") and answer["body"].endswith(".glb")

    status, data, ctype = fetch(server, answer["body"])
    assert status == 200 and ctype == "model/gltf-binary"
    assert len(data) < MESH_BYTES + FRAME_BYTES * len(joints)
    times, animated, gltf = animated_joints(data)
    assert np.allclose(times, np.arange(len(joints)) / answer["fps"], atol=1e-6)
    error = np.linalg.norm(animated - joints, axis=-1).max()
    assert error < 1e-3, f"body joints are {error * 1000:.3f} mm from the answer's"

    # one skinned mesh on the 22 joints, in HumanML3D order, with the parents the answer names
    (skin,) = gltf["skins"]
    assert skin["joints"] == list(range(NUM_JOINTS)) and len(gltf["meshes"]) == 1
    assert [n["name"] for n in gltf["nodes"][:NUM_JOINTS]] == list(JOINT_NAMES) and answer["parents"] == list(PARENTS)
    primitive = gltf["meshes"][0]["primitives"][0]
    assert {"POSITION", "NORMAL", "JOINTS_0", "WEIGHTS_0"} <= set(primitive["attributes"])

    # asked again (or with HEAD): the same bytes, built once
    assert fetch(server, answer["body"])[1] == data
    status, head, _ = fetch(server, answer["body"], method="HEAD")
    assert status == 200 and head == b""


def test_opened_motions_carry_a_body_too(server):
    status, raw, _ = fetch(server, "/api/files/0")
    assert status == 200
    answer = json.loads(raw)
    status, data, _ = fetch(server, answer["body"])
    assert status == 200
    _, animated, _ = animated_joints(data)
    # a synthetic walk's bones vary in length a little: the body keeps their mean, so it follows closely
    assert np.linalg.norm(animated - np.asarray(answer["joints"]), axis=-1).max() < 0.05


def test_only_the_last_bodies_are_kept_and_bad_numbers_are_refused(server):
    bodies = [json.loads(fetch(server, "/api/files/0")[1])["body"] for _ in range(MAX_BODIES + 1)]
    assert len(set(bodies)) == MAX_BODIES + 1
    status, raw, ctype = fetch(server, bodies[0])
    assert status == 404 and ctype == "application/json" and "only the last few motions" in json.loads(raw)["error"]
    assert fetch(server, bodies[-1])[0] == 200
    for path in ("/api/body/abc.glb", "/api/body/1", "/api/body/-1.glb", "/api/body/1.glb.glb",
                 "/api/body/99999999999999.glb"):
        status, raw, ctype = fetch(server, path)
        assert status == 400 and ctype == "application/json" and "body number must be a whole number" in json.loads(raw)["error"]
    assert fetch(server, "/api/body/999999.glb")[0] == 404


def test_vendored_three_is_served_from_an_allow_list(server):
    page = fetch(server, "/")[1].decode()
    assert '"three": "/static/vendor/three/build/three.module.js"' in page
    for name in ("build/three.module.js", "build/three.core.js", "examples/jsm/loaders/GLTFLoader.js",
                 "examples/jsm/utils/BufferGeometryUtils.js", "examples/jsm/utils/SkeletonUtils.js"):
        status, data, ctype = fetch(server, f"/static/vendor/three/{name}")
        assert status == 200 and ctype.startswith("text/javascript") and data == (VENDOR / name).read_bytes()
    for path in ("/static/vendor/three/LICENSE", "/static/vendor/three/build/../build/three.core.js",
                 "/static/vendor/three/build/", "/static/vendor/", "/static/vendor/three/build/%2e%2e/../../ui.js",
                 "/static/vendor/../ui.js", "/static/vendor/three/package.json"):
        assert fetch(server, path)[0] == 404, path
    served = static_files()
    assert all("/" not in name or name.startswith("vendor/three/") for name in served)
    assert not any(part.startswith(".") for name in served for part in name.split("/"))


def test_vendored_three_ships_with_its_licence_in_the_wheel():
    assert "MIT License" in (VENDOR / "LICENSE").read_text() and "three.js authors" in (VENDOR / "LICENSE").read_text()
    patterns = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["simdiff"]
    shipped = {p for pattern in patterns for p in (ROOT / "simdiff").glob(pattern)}
    needed = {p for p in STATIC.rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    assert needed and needed <= shipped, sorted(str(p.relative_to(STATIC)) for p in needed - shipped)
