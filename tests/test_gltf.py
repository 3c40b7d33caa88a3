"""glTF binary export: the file is read back here independently of the writer (header, chunks, accessors),
the animation is evaluated by hand and compared with the rigid motion's forward kinematics.

Optional checks: the Khronos validator when SIMDIFF_GLTF_VALIDATOR names a folder holding
``node_modules/gltf-validator`` (``npm install --prefix DIR gltf-validator``), and Blender's importer when
SIMDIFF_BLENDER_PYTHON names a Python with ``bpy``.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion import synthetic
from simdiff.motion.io import write_glb
from simdiff.motion.rigid import RigidMotion, fit
from simdiff.motion.skeleton import JOINT_NAMES, NUM_JOINTS, PARENTS

REPO = Path(__file__).resolve().parents[1]
COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def read_glb(path: Path) -> tuple[dict, bytes]:
    """The JSON document and BIN chunk of a glb, checking the container's framing."""
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    json_len, json_type = struct.unpack_from("<I4s", data, 12)
    assert json_type == b"JSON" and json_len % 4 == 0
    text = data[20:20 + json_len]
    assert text.rstrip(b" ") == text.rstrip()  # padded with spaces only
    bin_at = 20 + json_len
    bin_len, bin_type = struct.unpack_from("<I4s", data, bin_at)
    assert bin_type == b"BIN\0" and bin_len % 4 == 0 and bin_at + 8 + bin_len == len(data)
    return json.loads(text), data[bin_at + 8:]


def accessor(doc: dict, binary: bytes, index: int) -> np.ndarray:
    """Accessor ``index`` as a numpy array (count, width) (tightly packed views only)."""
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    assert "byteStride" not in view and view["byteOffset"] % 4 == 0
    dtype = np.dtype(COMPONENTS[acc["componentType"]])
    width = WIDTHS[acc["type"]]
    start = view["byteOffset"] + acc.get("byteOffset", 0)
    assert acc["count"] * width * dtype.itemsize <= view["byteLength"]
    return np.frombuffer(binary, dtype, acc["count"] * width, start).reshape(acc["count"], width)


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of quaternions (..., 4) x, y, z, w."""
    x, y, z, w = np.moveaxis(np.asarray(q, np.float64), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def animated_globals(doc: dict, binary: bytes) -> np.ndarray:
    """(T, nodes, 4, 4) world transforms of every node at each key time of the (only) animation."""
    nodes = doc["nodes"]
    anim = doc["animations"][0]
    times = accessor(doc, binary, anim["samplers"][0]["input"])[:, 0]
    frames = len(times)
    trs = np.zeros((frames, len(nodes), 10))
    for i, node in enumerate(nodes):
        trs[:, i, :3] = node.get("translation", [0, 0, 0])
        trs[:, i, 3:7] = node.get("rotation", [0, 0, 0, 1])
        trs[:, i, 7:] = node.get("scale", [1, 1, 1])
    for channel in anim["channels"]:
        sampler = anim["samplers"][channel["sampler"]]
        assert sampler["interpolation"] == "LINEAR"
        assert np.array_equal(accessor(doc, binary, sampler["input"])[:, 0], times)
        values = accessor(doc, binary, sampler["output"])
        span = {"translation": slice(0, 3), "rotation": slice(3, 7), "scale": slice(7, 10)}[channel["target"]["path"]]
        trs[:, channel["target"]["node"], span] = values
    local = np.tile(np.eye(4), (frames, len(nodes), 1, 1))
    local[..., :3, :3] = quat_matrix(trs[..., 3:7]) * trs[..., None, 7:]
    local[..., :3, 3] = trs[..., :3]
    parent = {c: i for i, n in enumerate(nodes) for c in n.get("children", [])}
    out = np.empty_like(local)
    done: set[int] = set()

    def visit(i: int) -> None:
        if i in done:
            return
        if i in parent:
            visit(parent[i])
            out[:, i] = out[:, parent[i]] @ local[:, i]
        else:
            out[:, i] = local[:, i]
        done.add(i)

    for i in range(len(nodes)):
        visit(i)
    return out


def rest_globals(doc: dict) -> np.ndarray:
    """(nodes, 4, 4) world transforms of the nodes as they rest (no animation)."""
    nodes = doc["nodes"]
    out = np.zeros((len(nodes), 4, 4))
    parent = {c: i for i, n in enumerate(nodes) for c in n.get("children", [])}
    for i in sorted(range(len(nodes)), key=lambda i: _depth(i, parent)):
        m = np.eye(4)
        m[:3, :3] = quat_matrix(np.array(nodes[i].get("rotation", [0, 0, 0, 1])))
        m[:3, 3] = nodes[i].get("translation", [0, 0, 0])
        out[i] = out[parent[i]] @ m if i in parent else m
    return out


def _depth(i: int, parent: dict[int, int]) -> int:
    return 0 if i not in parent else 1 + _depth(parent[i], parent)


def joint_nodes(doc: dict) -> list[int]:
    """Node index of each HumanML3D joint, by name."""
    names = [n.get("name") for n in doc["nodes"]]
    return [names.index(name) for name in JOINT_NAMES]


def turning_walk(frames: int = 60) -> RigidMotion:
    """A turning walk with bone lengths jittered like a generated motion, fitted on its own mean skeleton."""
    joints = synthetic.walk(frames, turn_rate=0.8).astype(np.float64)
    joints += np.random.default_rng(0).normal(0.0, 0.004, joints.shape)
    return fit(joints, None)


@pytest.fixture(scope="module")
def walk_glb(tmp_path_factory) -> tuple[RigidMotion, dict, bytes, Path]:
    motion = turning_walk()
    path = write_glb(tmp_path_factory.mktemp("glb") / "walk.glb", motion, fps=20)
    doc, binary = read_glb(path)
    return motion, doc, binary, path


def test_joint_world_positions_follow_the_forward_kinematics(walk_glb) -> None:
    motion, doc, binary, _ = walk_glb
    glob = animated_globals(doc, binary)
    positions = glob[:, joint_nodes(doc)][..., :3, 3]
    err = np.linalg.norm(positions - motion.joints, axis=-1)
    assert positions.shape == motion.joints.shape and err.max() < 1e-3
    times = accessor(doc, binary, doc["animations"][0]["samplers"][0]["input"])[:, 0]
    np.testing.assert_allclose(times, np.arange(len(times)) / 20.0, atol=1e-6)
    acc = doc["accessors"][doc["animations"][0]["samplers"][0]["input"]]
    assert acc["min"] == [0.0] and acc["max"] == pytest.approx([(len(times) - 1) / 20.0])
    # the hierarchy is HumanML3D's, with rest offsets as translations
    nodes = joint_nodes(doc)
    for j in range(1, NUM_JOINTS):
        assert nodes[j] in doc["nodes"][nodes[PARENTS[j]]]["children"]
        np.testing.assert_allclose(doc["nodes"][nodes[j]]["translation"], motion.offsets[j], atol=1e-6)


def test_rotations_are_unit_and_sign_continuous(walk_glb) -> None:
    _, doc, binary, _ = walk_glb
    anim = doc["animations"][0]
    paths = sorted(c["target"]["path"] for c in anim["channels"])
    assert paths.count("rotation") == NUM_JOINTS and paths.count("translation") == 1
    for channel in anim["channels"]:
        if channel["target"]["path"] != "rotation":
            continue
        q = accessor(doc, binary, anim["samplers"][channel["sampler"]]["output"]).astype(np.float64)
        np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-6)
        assert np.all(np.sum(q[1:] * q[:-1], axis=-1) >= 0)


def test_skin_weights_and_bind_pose(walk_glb) -> None:
    motion, doc, binary, _ = walk_glb
    (mesh_node,) = [i for i, n in enumerate(doc["nodes"]) if "mesh" in n]
    assert doc["nodes"][mesh_node]["skin"] == 0 and mesh_node in doc["scenes"][doc["scene"]]["nodes"]
    skin = doc["skins"][0]
    prim = doc["meshes"][0]["primitives"][0]
    assert prim.get("mode", 4) == 4 and "material" in prim
    pos = accessor(doc, binary, prim["attributes"]["POSITION"]).astype(np.float64)
    normals = accessor(doc, binary, prim["attributes"]["NORMAL"])
    idx = accessor(doc, binary, prim["attributes"]["JOINTS_0"]).astype(int)
    weights = accessor(doc, binary, prim["attributes"]["WEIGHTS_0"]).astype(np.float64)
    tris = accessor(doc, binary, prim["indices"]).reshape(-1, 3)
    acc = doc["accessors"][prim["attributes"]["POSITION"]]
    np.testing.assert_allclose(acc["min"], pos.min(axis=0), atol=1e-6)
    np.testing.assert_allclose(acc["max"], pos.max(axis=0), atol=1e-6)
    assert doc["accessors"][prim["attributes"]["JOINTS_0"]]["componentType"] in (5121, 5123)
    assert 1000 <= len(pos) <= 10000 and tris.max() < len(pos)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=-1), 1.0, atol=1e-5)
    np.testing.assert_allclose(weights.sum(axis=-1), 1.0, atol=1e-6)
    assert np.all(weights >= 0) and np.all((weights > 0).sum(axis=-1) <= 4)
    assert idx.max() < len(skin["joints"])
    for row_idx, row_w in zip(idx[:50:7], weights[:50:7]):
        used = row_idx[row_w > 0]
        assert len(set(used)) == len(used)
    # bind pose: the inverse bind matrices undo the rest transforms of the joint nodes
    ibm = accessor(doc, binary, skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
    rest = rest_globals(doc)[skin["joints"]]
    np.testing.assert_allclose(rest @ ibm, np.tile(np.eye(4), (len(ibm), 1, 1)), atol=1e-5)
    assert [doc["nodes"][j]["name"] for j in skin["joints"]] == list(JOINT_NAMES)
    # ... and the mesh is built around that rest skeleton: every vertex near a bone of its main joint
    rest_joints = rest[:, :3, 3]
    main = idx[np.arange(len(idx)), weights.argmax(axis=-1)]
    near = np.full(len(pos), np.inf)
    for j in range(1, NUM_JOINTS):
        a, b = rest_joints[PARENTS[j]], rest_joints[j]
        f = np.clip((pos - a) @ (b - a) / max(float((b - a) @ (b - a)), 1e-12), 0, 1)
        d = np.linalg.norm(pos - (a + f[:, None] * (b - a)), axis=-1)
        mine = (main == j) | (main == PARENTS[j])
        near[mine] = np.minimum(near[mine], d[mine])
    assert near.max() < 0.25 and np.median(near) < 0.1
    assert abs(pos[:, 1].min()) < 0.1  # the rest body stands on the floor


def skinned_body(doc: dict, binary: bytes, frames: list[int]) -> np.ndarray:
    """(len(frames), V, 3) body vertices posed by linear blend skinning at the given key frames."""
    prim = doc["meshes"][0]["primitives"][0]
    skin = doc["skins"][0]
    pos = accessor(doc, binary, prim["attributes"]["POSITION"]).astype(np.float64)
    idx = accessor(doc, binary, prim["attributes"]["JOINTS_0"]).astype(int)
    weights = accessor(doc, binary, prim["attributes"]["WEIGHTS_0"]).astype(np.float64)
    ibm = accessor(doc, binary, skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
    glob = animated_globals(doc, binary)[:, skin["joints"]]
    homo = np.concatenate([pos, np.ones((len(pos), 1))], axis=-1)
    return np.stack([np.einsum("nk,nkij,nj->ni", weights, (glob[t] @ ibm)[idx], homo)[:, :3] for t in frames])


def test_skinned_vertices_move_rigidly_with_their_bones(walk_glb) -> None:
    _, doc, binary, _ = walk_glb
    prim = doc["meshes"][0]["primitives"][0]
    skin = doc["skins"][0]
    pos = accessor(doc, binary, prim["attributes"]["POSITION"]).astype(np.float64)
    idx = accessor(doc, binary, prim["attributes"]["JOINTS_0"]).astype(int)
    weights = accessor(doc, binary, prim["attributes"]["WEIGHTS_0"]).astype(np.float64)
    ibm = accessor(doc, binary, skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
    glob = animated_globals(doc, binary)[:, skin["joints"]]
    single = weights.max(axis=-1) == 1.0
    main = idx[np.arange(len(idx)), weights.argmax(axis=-1)]
    frames = [0, glob.shape[0] - 1]
    for t, skinned in zip(frames, skinned_body(doc, binary, frames)):
        assert np.all(np.isfinite(skinned))
        before = np.linalg.norm(pos - np.linalg.inv(ibm)[main, :3, 3], axis=-1)
        after = np.linalg.norm(skinned - glob[t, main, :3, 3], axis=-1)
        np.testing.assert_allclose(after[single], before[single], atol=1e-5)


def test_196_frames_stay_under_a_megabyte(tmp_path: Path) -> None:
    motion = turning_walk(196)
    path = write_glb(tmp_path / "long.glb", motion)
    size = path.stat().st_size
    assert size <= 1_000_000, size
    doc, binary = read_glb(path)
    assert doc["accessors"][doc["animations"][0]["samplers"][0]["input"]]["count"] == 196
    positions = animated_globals(doc, binary)[:, joint_nodes(doc)][..., :3, 3]
    assert np.linalg.norm(positions - motion.joints, axis=-1).max() < 1e-3


def test_skeleton_only_and_single_frame(tmp_path: Path) -> None:
    motion = turning_walk(12)
    one = RigidMotion(motion.local[:1], motion.root[:1], motion.offsets)
    doc, binary = read_glb(write_glb(tmp_path / "one.glb", one, body=False))
    assert "meshes" not in doc and "skins" not in doc
    positions = animated_globals(doc, binary)[:, joint_nodes(doc)][..., :3, 3]
    assert np.linalg.norm(positions - one.joints, axis=-1).max() < 1e-3


@pytest.mark.parametrize("change, needle", [
    (lambda m: RigidMotion(m.local[:, :21], m.root, m.offsets[:21]), "22"),
    (lambda m: RigidMotion(m.local[:0], m.root[:0], m.offsets), "T >= 1"),
    (lambda m: RigidMotion(m.local, np.where(np.arange(len(m.root))[:, None] == 3, np.nan, m.root), m.offsets),
     "NaN"),
])
def test_bad_motion_is_one_line(tmp_path: Path, change, needle: str) -> None:
    with pytest.raises(SimdiffError) as info:
        write_glb(tmp_path / "bad.glb", change(turning_walk(8)))
    assert needle in str(info.value) and "\n" not in str(info.value)
    assert not (tmp_path / "bad.glb").exists()


def test_convert_npy_to_glb(tmp_path: Path, capsys) -> None:
    from simdiff.cli.main import main

    joints = synthetic.walk(30).astype(np.float32)
    np.save(tmp_path / "walk.npy", joints)
    assert main(["convert", str(tmp_path / "walk.npy"), str(tmp_path / "walk.glb")]) == 0
    assert "walk.glb" in capsys.readouterr().out
    doc, binary = read_glb(tmp_path / "walk.glb")
    positions = animated_globals(doc, binary)[:, joint_nodes(doc)][..., :3, 3]
    assert np.linalg.norm(positions - fit(joints, None).joints, axis=-1).max() < 1e-3
    assert main(["convert", str(tmp_path / "walk.npy"), str(tmp_path / "f.glb"), "--to", "features"]) == 2
    err = capsys.readouterr().err
    assert "--to features needs a .npy output" in err and err.count("\n") == 1


def test_convert_bad_joints_is_one_line(tmp_path: Path, capsys) -> None:
    from simdiff.cli.main import main

    bad = synthetic.walk(10).astype(np.float32)
    bad[4, 3] = np.nan
    np.save(tmp_path / "nan.npy", bad)
    assert main(["convert", str(tmp_path / "nan.npy"), str(tmp_path / "nan.glb")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not (tmp_path / "nan.glb").exists()


def test_write_motion_glb_kind(tmp_path: Path) -> None:
    from simdiff.product.outputs import write_motion
    from simdiff.product.request import parse_formats

    assert "glb" in parse_formats("npy,glb")
    joints = synthetic.jump(24).astype(np.float32)
    written = write_motion(tmp_path / "sample0", joints, np.zeros((24, 263), np.float32), ["glb"])
    assert list(written) == ["glb"] and written["glb"].name == "sample0.glb"
    doc, binary = read_glb(written["glb"])
    positions = animated_globals(doc, binary)[:, joint_nodes(doc)][..., :3, 3]
    assert np.linalg.norm(positions - fit(joints, None).joints, axis=-1).max() < 1e-3


def test_generate_writes_a_glb(tmp_path: Path, capsys) -> None:
    from test_generate_cli import save_tiny

    from simdiff.cli.main import main

    model = save_tiny(tmp_path / "model")
    code = main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--model", str(model),
                 "--out", str(tmp_path / "o"), "--format", "npy,bvh,glb", "-q"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "sample0.glb" in [Path(p).name for p in captured.out.split()]
    doc, binary = read_glb(tmp_path / "o" / "sample0.glb")
    joints = np.load(tmp_path / "o" / "sample0_joints.npy")
    positions = animated_globals(doc, binary)[:, joint_nodes(doc)][..., :3, 3]
    assert positions.shape == (10, 22, 3)
    assert np.linalg.norm(positions - fit(joints, None).joints, axis=-1).max() < 1e-3


@pytest.mark.skipif(not os.environ.get("SIMDIFF_GLTF_VALIDATOR") or shutil.which("node") is None,
                    reason="SIMDIFF_GLTF_VALIDATOR not set (or no node)")
def test_khronos_validator_finds_no_error(walk_glb) -> None:
    *_, path = walk_glb
    root = Path(os.environ["SIMDIFF_GLTF_VALIDATOR"])
    module = root / "node_modules" / "gltf-validator" if (root / "node_modules").is_dir() else root
    script = ("const v=require(process.argv[1]);const fs=require('fs');"
              "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2])),{maxIssues:100})"
              ".then(r=>console.log(JSON.stringify(r.issues))).catch(e=>{console.error(String(e));process.exit(1);});")
    out = subprocess.run(["node", "-e", script, str(module), str(path)], capture_output=True, text=True,
                         timeout=120, check=True).stdout
    issues = json.loads(out)
    print(f"validator: {issues['numErrors']} errors, {issues['numWarnings']} warnings, {issues['numInfos']} infos, "
          f"{issues['numHints']} hints: {[m['code'] for m in issues['messages']]}")
    assert issues["numErrors"] == 0, issues["messages"]


@pytest.mark.skipif(not os.environ.get("SIMDIFF_BLENDER_PYTHON"), reason="SIMDIFF_BLENDER_PYTHON not set")
def test_blender_imports_our_glb(walk_glb, tmp_path: Path) -> None:
    motion, doc, binary, path = walk_glb
    np.save(tmp_path / "walk.npy", motion.joints)
    frames = len(motion.joints)
    np.save(tmp_path / "body.npy", skinned_body(doc, binary, [0, frames // 2, frames - 1]))
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    out = subprocess.run(
        [os.environ["SIMDIFF_BLENDER_PYTHON"], str(Path(__file__).parent / "gltf_blender_check.py"), str(path),
         str(tmp_path / "walk.npy"), "20", str(tmp_path / "body.npy")],
        capture_output=True, text=True, env=env, timeout=300, check=True, cwd=tmp_path,
    ).stdout
    print("\n".join(out.strip().splitlines()[-2:]))
    assert "armature modifier True" in out
    assert float(re.search(r"reference: mean [0-9.]+ mm, max ([0-9.]+) mm", out).group(1)) < 1.0
    assert float(re.search(r"skinning: max ([0-9.]+) mm", out).group(1)) < 1.0
