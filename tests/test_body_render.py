"""Body rendering with MuJoCo's offscreen renderer: sizes, non-blank frames, shadows, files, errors.

Everything that needs OpenGL skips cleanly when neither EGL nor OSMesa works here.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.errors import SimdiffError  # noqa: E402
from simdiff.sim import synthetic  # noqa: E402
from simdiff.viz import body as B  # noqa: E402

W, H = 240, 180


@pytest.fixture(scope="module")
def backend() -> str:
    try:
        return B.gl_backend()
    except SimdiffError as exc:
        pytest.skip(f"no headless OpenGL: {exc}")


@pytest.fixture(scope="module")
def standing_qpos() -> np.ndarray:
    from simdiff.sim.humanoid import load_model

    return load_model().qpos0.copy()


@pytest.fixture(scope="module")
def pair(backend, standing_qpos):
    """The standing humanoid rendered with shadows on and off, same camera."""
    images = []
    for shadows in (True, False):
        style = B.BodyStyle(shadows=shadows, multisample=0)
        with B.BodyRenderer(W, H, style, B.BodyCamera(distance=3.0, azimuth=120, elevation=-20), backend) as r:
            images.append(r.render(standing_qpos, (0.0, 0.0, 0.85)))
    return images


def _body_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of the default (blue) body colour."""
    rgb = img.astype(int)
    return (rgb[..., 2] - rgb[..., 0] > 60) & (rgb[..., 2] > 120)


def test_frame_size_and_content(pair):
    on, _ = pair
    assert on.shape == (H, W, 3) and on.dtype == np.uint8
    assert on.std() > 20  # not blank
    body = _body_mask(on)
    assert body.sum() > 500  # the blue humanoid is in view ...
    rows, cols = np.nonzero(body)
    assert abs(cols.mean() - W / 2) < W / 6 and abs(rows.mean() - H / 2) < H / 4  # ... near the image centre


def test_shadow_darkens_ground_next_to_body(pair):
    on, off = pair
    lum_on, lum_off = on.astype(float).mean(-1), off.astype(float).mean(-1)
    floor = np.zeros((H, W), dtype=bool)
    floor[H // 2 :] = True  # the lower half is floor (the camera looks down at a standing body)
    floor &= ~_body_mask(on) & ~_body_mask(off)
    # turning shadows on scales the lit floor by one factor (MuJoCo's extra light pass) ...
    ratio = lum_on / np.maximum(lum_off, 1.0)
    lit = np.median(ratio[floor])
    assert np.percentile(ratio[floor], 25) > 0.98 * lit
    # ... except where the body blocks the sun: that is the shadow
    shadow = floor & (ratio < 0.75 * lit)
    assert shadow.sum() > 150, "no shadow on the ground"
    rows = np.nonzero(shadow)[0]
    assert np.median(rows) > np.median(np.nonzero(_body_mask(on))[0])  # on the floor, below the pelvis
    # the ground under the body is much darker than the ground far from it (whatever checker colour)
    far = floor & ~shadow
    assert lum_on[shadow].mean() < np.percentile(lum_on[far], 5) - 60


def test_render_mjcf_adds_visuals_only():
    import mujoco

    from simdiff.sim.humanoid import build_mjcf, load_model

    sim = load_model()
    xml = B.render_mjcf(width=800, height=600)
    model = mujoco.MjModel.from_xml_string(xml)
    assert (model.nq, model.nv, model.nbody, model.njnt, model.nu) == (sim.nq, sim.nv, sim.nbody, sim.njnt, sim.nu)
    assert np.allclose(model.body_mass, sim.body_mass) and np.allclose(model.qpos0, sim.qpos0)
    assert model.vis.global_.offwidth == 800 and model.vis.global_.offheight == 600
    assert model.ntex == 2 and model.nmat == 3 and model.light_castshadow.tolist() == [1]
    assert "skybox" not in build_mjcf() and "material" not in build_mjcf()  # the simulation MJCF is untouched


def test_motion_qpos_joints_and_passthrough():
    from simdiff.sim.retarget import qpos_to_joints
    from simdiff.sim.humanoid import load_model

    model = load_model()
    joints = synthetic.squat(12)
    q = B.motion_qpos(joints, model)
    assert q.shape == (12, model.nq)
    back = qpos_to_joints(model, q)
    assert np.abs(back - joints).max() < 0.03  # the simulator's IK reproduces its own poses
    assert np.array_equal(B.motion_qpos(q, model), q)
    with pytest.raises(SimdiffError, match=r"\(5, 21, 3\)"):
        B.motion_qpos(np.zeros((5, 21, 3)), model)


def test_camera_path_follows_root():
    q = np.zeros((40, 76))
    q[:, 0] = np.linspace(0, 2, 40)
    q[:, 2] = 0.9
    look = B.camera_path(q, 20.0)
    assert look.shape == (40, 3) and np.allclose(look[:, 2], B.BodyCamera().height)
    assert np.all(np.diff(look[:, 0]) >= 0) and abs(look[20, 0] - q[20, 0]) < 0.05


def test_render_body_files(backend, tmp_path):
    import imageio.v3 as iio

    motions = [synthetic.squat(6), synthetic.standing(4)]
    style = B.BodyStyle(multisample=0, shadow_size=512)
    mp4 = B.render_body(motions, tmp_path / "a.mp4", captions=["squat", "stand"], size=(96, 80), style=style,
                        progress=False)
    video = iio.imread(mp4)
    assert video.shape == (6, 80, 192, 3)  # two panels side by side, max(T) frames
    gif = B.render_body(motions[1], tmp_path / "a.gif", size=(64, 48), style=style, progress=False)
    assert iio.imread(gif).shape[:3] == (4, 48, 64)
    png = B.render_body(motions, tmp_path / "a.png", size=(64, 72), n_frames=3, style=style, progress=False)
    strip = iio.imread(png)
    assert strip.shape[:2] == (2 * 72, 3 * 64) and strip.std() > 10


def test_render_body_bad_input(tmp_path):
    with pytest.raises(SimdiffError, match="suffix"):
        B.render_body(synthetic.standing(4), tmp_path / "x.avi")
    with pytest.raises(SimdiffError, match="width"):
        B.render_body(synthetic.standing(4), tmp_path / "x.mp4", size=(4, 48))


def test_no_backend_names_what_to_install(monkeypatch):
    import ctypes.util

    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.delenv("PYOPENGL_PLATFORM", raising=False)
    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    with pytest.raises(SimdiffError) as err:
        B.gl_backend.__wrapped__()
    msg = str(err.value)
    assert "\n" not in msg and "libegl" in msg and "libosmesa6" in msg


def test_cli_render_body_png(backend, tmp_path, capsys):
    from simdiff.cli.main import main

    src = tmp_path / "squat.npy"
    np.save(src, synthetic.squat(8))
    out = tmp_path / "body.png"
    assert main(["render", str(src), "--body", "--out", str(out), "--frames", "2", "--size", "64", "64"]) == 0
    import imageio.v3 as iio

    assert iio.imread(out).shape[:2] == (64, 128)
    capsys.readouterr()
    assert main(["render", str(src), "--body", "--filmstrip", "--out", str(tmp_path / "b.mp4")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("simdiff: error:") and "b.mp4" in err[0]
