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


def _mujoco_pixels(points: np.ndarray, lookats: np.ndarray, camera, size: tuple[int, int]) -> np.ndarray:
    """(T, N, 2) pixel (column, row) of world points (T, N, 3) through MuJoCo's own camera.

    Per frame ``mjv_updateScene`` places the free camera at the look-at point as
    :class:`BodyRenderer` does, and the points are projected with the eye position, axes and
    frustum MuJoCo hands to OpenGL (``MjvScene.camera``).
    """
    import mujoco

    model = B._copy_model(B._render_model(B.BodyStyle(), 640, 480))
    model.vis.global_.fovy = camera.fovy
    data = mujoco.MjData(model)
    scene = mujoco.MjvScene(model, maxgeom=500)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.azimuth, cam.elevation = camera.distance, camera.azimuth, camera.elevation
    w, h = size
    out = np.empty((*points.shape[:2], 2))
    for t, look in enumerate(lookats):
        cam.lookat[:] = look
        mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), mujoco.MjvPerturb(), cam,
                               mujoco.mjtCatBit.mjCAT_ALL.value, scene)
        gl = scene.camera[0]
        fwd, up = np.asarray(gl.forward), np.asarray(gl.up)
        v = points[t] - np.asarray(gl.pos)
        depth = v @ fwd
        assert (depth > gl.frustum_near).all()
        half_h = (gl.frustum_top - gl.frustum_bottom) / 2
        half_w = gl.frustum_width / 2 if gl.frustum_width else half_h * w / h
        sx = (v @ np.cross(fwd, up)) * gl.frustum_near / depth - gl.frustum_center
        sy = (v @ up) * gl.frustum_near / depth - (gl.frustum_top + gl.frustum_bottom) / 2
        out[t] = np.stack([(sx / half_w + 1) / 2 * w, (1 - sy / half_h) / 2 * h], axis=-1)
    return out


def _box_corners(boxes) -> np.ndarray:
    centres, axes, half = boxes
    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
    corners = centres[:, :, None, :] + np.einsum("tgij,gkj->tgki", axes, signs[None] * half[:, None, :])
    return corners.reshape(len(centres), -1, 3)


def _framing(motions, size):
    """Per panel (joint pixels, geom-corner pixels) through MuJoCo's camera, and the camera used."""
    from simdiff.sim.humanoid import hml_to_world, load_model
    from simdiff.viz.camera import geom_boxes

    clips, camera = B.body_view(motions, None, 20.0, size)
    out = []
    for m, clip in zip(motions, clips):
        joints = _mujoco_pixels(hml_to_world(np.asarray(m, dtype=np.float64)), clip.lookat, camera, size)
        geoms = _mujoco_pixels(_box_corners(geom_boxes(load_model(), clip.qpos)), clip.lookat, camera, size)
        out.append((joints, geoms))
    return out, camera


def _border(px: np.ndarray, size) -> float:
    """Smallest distance (px) of any point to the image border (negative: outside)."""
    w, h = size
    return float(min(px[..., 0].min(), w - px[..., 0].max(), px[..., 1].min(), h - px[..., 1].max()))


@pytest.mark.parametrize("name", ["jump 2.5 m", "walk", "long walk"])
def test_fitted_camera_keeps_every_joint_in_view(name):
    from simdiff.motion import synthetic as hml

    motion = {"jump 2.5 m": lambda: hml.jump(80, height=2.5, airtime=1.4), "walk": lambda: hml.walk(60),
              "long walk": lambda: hml.walk(300, speed=1.5)}[name]()
    size = (320, 360)
    [(joints, geoms)], camera = _framing([motion], size)
    margin_px = camera.margin * min(size) / 2
    assert _border(joints, size) >= margin_px - 0.5, "a joint is outside the image or its margin"
    assert _border(geoms, size) >= margin_px - 0.5, "a body part is outside the image or its margin"
    # the fit is tight: some body part touches the margin (nothing is zoomed out for nothing)
    if camera.distance > camera.min_distance:
        tight = min(geoms[..., 1].min(), size[1] - geoms[..., 1].max()) / (size[1] / 2)
        side = min(geoms[..., 0].min(), size[0] - geoms[..., 0].max()) / (size[0] / 2)
        assert min(tight, side) == pytest.approx(camera.margin, abs=1e-3)
    if name == "jump 2.5 m":
        assert camera.distance > B.BodyCamera().distance  # the old fixed camera cropped the apex


def test_side_by_side_panels_share_one_camera():
    from simdiff.motion import synthetic as hml

    size = (320, 360)
    low, high = hml.jump(80, height=0.4, airtime=0.57), hml.jump(80, height=2.5, airtime=1.4)
    panels, camera = _framing([low, high], size)
    for joints, geoms in panels:  # both fit in the shared camera
        assert _border(joints, size) > 0 and _border(geoms, size) > 0
    alone = B.body_view([low], None, 20.0, size)[1]
    assert camera.distance > alone.distance + 1.0  # the low jump is seen from as far as the high one
    clips, shared = B.body_view([high, low], None, 20.0, size)
    assert (shared.azimuth, shared.elevation, shared.distance, shared.height) == pytest.approx(
        (camera.azimuth, camera.elevation, camera.distance, camera.height))  # order does not matter
    assert all(np.allclose(c.lookat[:, 2], shared.height) for c in clips)


def test_unfitted_camera_is_used_as_given():
    cam = B.BodyCamera(distance=3.0, fit=False)
    clips, used = B.body_view([synthetic.squat(6)], None, 20.0, (64, 64), camera=cam)
    assert used == cam and np.allclose(clips[0].lookat[:, 2], cam.height)


def test_render_uses_the_shared_camera_for_every_panel(backend, monkeypatch):
    from simdiff.motion import synthetic as hml

    seen = []
    render = B.BodyRenderer.render

    def spy(self, qpos, lookat, text="", text2=""):
        seen.append((self.cam.azimuth, self.cam.elevation, self.cam.distance, float(lookat[2])))
        return render(self, qpos, lookat, text, text2)

    monkeypatch.setattr(B.BodyRenderer, "render", spy)
    motions = [hml.jump(12, height=0.4, start=2, airtime=0.4), hml.jump(12, height=2.5, start=2, airtime=0.4)]
    style = B.BodyStyle(multisample=0, shadow_size=256)
    frames = list(B.body_frames(motions, size=(48, 54), style=style))
    assert len(frames) == 12 and len(seen) == 24
    assert len(set(seen)) == 1  # one azimuth, elevation, distance and look-at height for all panels and frames
    _, camera = B.body_view(motions, None, 20.0, (48, 54))
    assert seen[0] == pytest.approx((camera.azimuth, camera.elevation, camera.distance, camera.height), abs=1e-5)


def test_rendered_body_stays_inside_the_image(backend):
    """The real image agrees with the projection: at a 2.5 m apex the body is whole, its top near the prediction."""
    from simdiff.motion import synthetic as hml

    motion = hml.jump(80, height=2.5, airtime=1.4)
    size = (160, 180)
    [(_, geoms)], camera = _framing([motion], size)
    clips, _ = B.body_view([motion], None, 20.0, size)
    apex = int(np.argmax(clips[0].qpos[:, 2]))
    style = B.BodyStyle(multisample=0, shadows=False, captions=False)
    with B.BodyRenderer(*size, style, camera) as r:
        image = r.render(clips[0].qpos[apex], clips[0].lookat[apex])
    body = _body_mask(image)
    rows, cols = np.nonzero(body)
    assert body.sum() > 200
    assert rows.min() > 2 and cols.min() > 2 and cols.max() < size[0] - 3 and rows.max() < size[1] - 3
    # the top of the rendered body is where the camera math puts it (box corners are a few px higher)
    assert geoms[apex, :, 1].min() - 2 <= rows.min() <= geoms[apex, :, 1].min() + 10


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
