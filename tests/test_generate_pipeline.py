"""The pipeline behind ``simdiff generate`` on a tiny random model: files, shapes, seeds, --compare, GIF writer."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.diffusion.config import SamplingConfig
from simdiff.motion.rigid import bone_lengths, joints_from_features
from simdiff.product.pipeline import Timer, run_generation, sample_motions
from simdiff.product.request import GenerationRequest, build_request
from simdiff.train.testing import tiny_generator
from simdiff.viz.video import write_gif

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def req(text: str, steps: int, **kwargs) -> GenerationRequest:
    """A checked request sampled with ``steps`` DDIM steps (the other settings: SamplingConfig's defaults)."""
    return build_request(text, sampling=SamplingConfig(steps=steps), **kwargs)


def test_files_shapes_and_metadata(tmp_path: Path) -> None:
    request = req("a person jumps forward", 3, gravity=-3.7, wind=(2.0, 0.0), length_s=0.6, seed=4,
                            formats="npy,bvh,gif")
    timer = Timer()
    meta, paths = run_generation(tiny_generator(), request, tmp_path, tmp_path, timer, quiet=True)
    names = sorted(p.name for p in paths)
    assert names == ["generation.json", "sample0.bvh", "sample0.gif", "sample0_features.npy", "sample0_joints.npy"]
    assert all(p.is_file() for p in paths)
    feats = np.load(tmp_path / "sample0_features.npy")
    joints = np.load(tmp_path / "sample0_joints.npy")
    assert feats.shape == (12, 263) and joints.shape == (12, 22, 3) and joints.dtype == np.float32
    np.testing.assert_array_equal(joints, joints_from_features(feats))  # the rigid fit of the features' positions
    assert float(np.ptp(bone_lengths(joints), axis=0).max()) < 1e-5
    from simdiff.motion.io.bvh import read_bvh
    from simdiff.motion.skeleton import JOINT_NAMES

    rig = read_bvh(tmp_path / "sample0.bvh", scale=1.0)
    back = rig.positions[:, [rig.index(n) for n in JOINT_NAMES]]
    assert back.shape[0] == 12 and float(np.abs(back - joints).max()) < 1e-5  # the BVH is the written joints
    from PIL import Image

    with Image.open(tmp_path / "sample0.gif") as im:
        assert im.n_frames == 12 and im.info["duration"] == 50
    saved = json.loads((tmp_path / "generation.json").read_text())
    assert saved == meta
    assert saved["prompt"] == "a person jumps forward" and saved["environment"] == {"gravity": -3.7, "wind": [2.0, 0.0]}
    assert (saved["sampler"], saved["steps"], saved["guidance"], saved["alpha"], saved["seed"]) == ("ddim", 3, 2.5, 1.0, 4)
    assert saved["samples"][0]["files"]["gif"] == "sample0.gif" and saved["samples"][0]["seed"] == 4
    assert {"load_model", "encode_text", "sample", "write_bvh", "render_gif", "total"} - set(saved["timings_s"]) == {"load_model"}
    assert saved["timings_s"]["total"] > 0


def test_sample_k_uses_seed_plus_k_and_env_matters() -> None:
    gen = tiny_generator()
    two = sample_motions(gen, req("walk", 3, length_s=0.5, seed=5, num_samples=2), Timer(), quiet=True)
    one = sample_motions(gen, req("walk", 3, length_s=0.5, seed=6), Timer(), quiet=True)
    assert [s.seed for s in two] == [5, 6]
    np.testing.assert_array_equal(two[1].features, one[0].features)
    assert not np.allclose(two[0].features, two[1].features)
    moon = sample_motions(gen, req("walk", 3, gravity=-1.6, length_s=0.5, seed=6), Timer(), quiet=True)
    assert np.abs(moon[0].features - one[0].features).max() > 1e-3


def test_compare_same_noise_per_environment(tmp_path: Path) -> None:
    request = req("a person jumps", 2, length_s=0.5, compare="gravity=-9.81,-1.6", num_samples=1,
                            formats="npy,gif")
    gen = tiny_generator()
    meta, paths = run_generation(gen, request, tmp_path, tmp_path, Timer(), quiet=True)
    names = sorted(p.name for p in paths)
    assert names == ["compare_sample0.gif", "generation.json", "gravity-1.6_sample0_features.npy",
                     "gravity-1.6_sample0_joints.npy", "gravity-9.81_sample0_features.npy",
                     "gravity-9.81_sample0_joints.npy"]
    assert meta["compare"] == {"component": "gravity", "values": [-9.81, -1.6]} and meta["environment"] is None
    from PIL import Image

    with Image.open(tmp_path / "compare_sample0.gif") as im:
        width = im.size[0]
    with Image.open(paths[0]) as im:
        assert im.size[0] == width
    # each compared motion equals a plain run under that environment with the same seed
    earth = sample_motions(gen, req("a person jumps", 2, length_s=0.5), Timer(), quiet=True)[0]
    np.testing.assert_array_equal(np.load(tmp_path / "gravity-9.81_sample0_features.npy"), earth.features)
    # with zero-initialised (fresh) adapters φ has no effect: same noise gives the same motion
    fresh = tiny_generator(active_adapters=False)
    runs = sample_motions(fresh, request, Timer(), quiet=True)
    np.testing.assert_allclose(runs[0].features, runs[1].features, atol=1e-6)


def test_backbone_model_ignores_environment(tmp_path: Path) -> None:
    gen = tiny_generator(sim=False)
    request = req("walk", 2, gravity=-1.6, length_s=0.5, formats="npy").with_envs(
        build_request("walk").envs)
    meta, _ = run_generation(gen, request, tmp_path, tmp_path, Timer(), quiet=True)
    assert meta["environment"] is None and meta["alpha"] is None and meta["samples"][0]["environment"] is None
    assert "backbone" in meta["model"]["kind"]


def test_mp4_output(tmp_path: Path) -> None:
    request = req("walk", 1, length_s=0.5, formats="mp4")
    _, paths = run_generation(tiny_generator(), request, tmp_path, tmp_path, Timer(), quiet=True)
    assert [p.name for p in paths] == ["sample0.mp4", "generation.json"]
    assert (tmp_path / "sample0.mp4").stat().st_size > 1000


def test_shared_palette_gif_is_faithful(tmp_path: Path) -> None:
    from PIL import Image

    rng = np.random.default_rng(0)
    base = np.full((60, 80, 3), 255, np.uint8)
    colours = rng.integers(0, 255, (5, 3), dtype=np.uint8)
    frames = []
    for t in range(10):
        f = base.copy()
        for i, c in enumerate(colours):
            f[5 + 10 * i: 12 + 10 * i, 4 * t: 4 * t + 20] = c
        frames.append(f)
    assert write_gif(iter(frames), tmp_path / "a.gif", fps=20) == 10
    with Image.open(tmp_path / "a.gif") as im:
        assert im.n_frames == 10 and im.info["duration"] == 50 and im.info.get("loop") == 0
        for t in (0, 9):
            im.seek(t)
            back = np.asarray(im.convert("RGB"), dtype=int)
            assert np.abs(back - frames[t]).max() <= 8  # few flat colours survive exactly (or nearly)
    from simdiff.errors import SimdiffError

    with pytest.raises(SimdiffError, match="no frames"):
        write_gif([], tmp_path / "b.gif", fps=20)
