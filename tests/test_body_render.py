"""Body rendering: skinning as the glTF export binds it, the render model's mesh, framing, pixels, files, errors.

Everything that needs OpenGL skips cleanly when neither EGL nor OSMesa works here.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.errors import SimdiffError  # noqa: E402
from simdiff.motion import synthetic as hml  # noqa: E402
from simdiff.motion.body_mesh import build_body, rest_positions, skin  # noqa: E402
from simdiff.motion.rigid import RigidMotion, fit  # noqa: E402
from simdiff.motion.skeleton import CANONICAL_OFFSETS, NUM_JOINTS, PARENTS  # noqa: E402
from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.humanoid import hml_to_world  # noqa: E402
from simdiff.viz import body as B  # noqa: E402
from simdiff.viz import body_scene as S  # noqa: E402

W, H = 240, 180


@pytest.fixture(scope="module")
def backend() -> str:
    try:
        return S.gl_backend()
    except SimdiffError as exc:
        pytest.skip(f"no headless OpenGL: {exc}")


# --------------------------------------------------------------------------------------
# skinning
# --------------------------------------------------------------------------------------


def _gltf_skinning(mesh, motion: RigidMotion, mesh_root: np.ndarray, rest_root: np.ndarray) -> np.ndarray:
    """(T, V, 3) vertices posed the glTF way: node matrices T(offset) R(local) chained from the pelvis node,
    inverse bind matrices the inverse rest transforms of a skeleton resting at ``rest_root``."""
    frames = len(motion.root)
    glob = np.zeros((frames, NUM_JOINTS, 4, 4))
    for j in range(NUM_JOINTS):
        node = np.tile(np.eye(4), (frames, 1, 1))
        node[:, :3, :3] = motion.local[:, j]
        node[:, :3, 3] = motion.root if j == 0 else motion.offsets[j]
        glob[:, j] = node if PARENTS[j] < 0 else glob[:, PARENTS[j]] @ node
    ibm = np.tile(np.eye(4), (NUM_JOINTS, 1, 1))
    ibm[:, :3, 3] = -rest_positions(motion.offsets, rest_root)
    # the mesh rests where the skeleton rests: move it from mesh_root to rest_root first
    homo = np.concatenate([mesh.positions - mesh_root + rest_root, np.ones((len(mesh.positions), 1))], axis=-1)
    idx, w = mesh.joints.astype(int), mesh.weights.astype(np.float64)
    return np.einsum("vk,tvkij,vj->tvi", w, (glob @ ibm)[:, idx], homo)[..., :3]


def test_skin_of_the_rest_pose_is_the_mesh():
    root = np.array([0.3, 0.95, -0.2])
    mesh = build_body(CANONICAL_OFFSETS, root)
    rest = RigidMotion(np.tile(np.eye(3), (2, NUM_JOINTS, 1, 1)), np.tile(root, (2, 1)), CANONICAL_OFFSETS)
    verts, normals = skin(mesh, rest, root)
    assert verts.shape == normals.shape == (2, len(mesh.positions), 3) and verts.dtype == np.float32
    np.testing.assert_allclose(verts, np.broadcast_to(mesh.positions, verts.shape), atol=1e-6)
    np.testing.assert_allclose(normals, np.broadcast_to(mesh.normals, normals.shape), atol=1e-6)


def test_skin_matches_the_gltf_binding_and_follows_the_joints():
    joints = hml.walk(30)
    motion = fit(joints, None)
    mesh = build_body(motion.offsets, motion.root[0])
    verts, normals = skin(mesh, motion, motion.root[0])
    from simdiff.motion.io.gltf_writer import rest_root

    expected = _gltf_skinning(mesh, motion, motion.root[0], rest_root(motion.offsets, motion.root))
    assert np.abs(verts - expected).max() < 1e-5
    np.testing.assert_allclose(np.linalg.norm(normals, axis=-1), 1.0, atol=1e-5)
    assert np.abs(motion.joints - joints).max() < 1e-4  # the own-skeleton fit reproduces the joints ...
    # ... and the body goes where they go: the pelvis vertex cloud's centre tracks the pelvis
    pelvis = (mesh.joints[:, 0] == 0) & (mesh.weights[:, 0] == 1.0)
    centre = verts[:, pelvis].mean(axis=1)
    assert np.abs((centre - centre[0]) - (joints[:, 0] - joints[0, 0])).max() < 0.02


def test_a_vertex_bound_to_one_joint_moves_rigidly_with_it():
    motion = fit(hml.jump(40, height=0.6, start=10, airtime=0.5), None)
    root = motion.root[0]
    mesh = build_body(motion.offsets, root)
    verts, _ = skin(mesh, motion, root)
    rest = rest_positions(motion.offsets, root)
    posed = motion.joints.astype(np.float64)
    from simdiff.motion.rigid import global_rotations

    glob = global_rotations(motion.local)
    for j in (4, 15, 20):  # left knee (shin), head, left wrist (hand)
        alone = np.flatnonzero((mesh.joints[:, 0] == j) & (mesh.weights[:, 0] == 1.0))
        assert len(alone) > 10
        rel = mesh.positions[alone] - rest[j]
        want = np.einsum("tab,vb->tva", glob[:, j], rel) + posed[:, j, None]
        assert np.abs(verts[:, alone] - want).max() < 1e-5
        # rigid: distances to the joint are those at rest
        dist = np.linalg.norm(verts[:, alone] - posed[:, j, None], axis=-1)
        np.testing.assert_allclose(dist, np.broadcast_to(np.linalg.norm(rel, axis=-1), dist.shape), atol=1e-5)


def test_every_skeleton_gives_the_render_model_topology():
    rng = np.random.default_rng(3)
    template = S.template_body()
    for _ in range(5):
        mesh = build_body(CANONICAL_OFFSETS * rng.uniform(0.7, 1.3, (NUM_JOINTS, 3)))
        assert mesh.positions.shape == template.positions.shape
        assert np.array_equal(mesh.triangles, template.triangles)


# --------------------------------------------------------------------------------------
# the render model
# --------------------------------------------------------------------------------------


def test_render_model_holds_the_body_mesh_in_world_coordinates():
    import mujoco

    model = S._render_model(B.BodyStyle(), 800, 600)
    mesh = S.template_body()
    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "body")
    mid = model.geom_dataid[geom]
    assert model.mesh_vertnum[mid] == len(mesh.positions) and model.mesh_facenum[mid] == len(mesh.triangles)
    assert np.allclose(model.geom_pos[geom], 0) and np.allclose(model.geom_quat[geom], [1, 0, 0, 0])
    adr = model.mesh_vertadr[mid]
    # with the geom at the origin the stored vertices are world points: the template in Z-up world
    assert np.abs(model.mesh_vert[adr:adr + len(mesh.positions)] - hml_to_world(mesh.positions)).max() < 1e-4
    assert model.geom_contype[geom] == 0 and model.geom_conaffinity[geom] == 0
    assert model.vis.global_.offwidth == 800 and model.vis.global_.offheight == 600
    assert model.ntex == 2 and model.nmat == 2 and model.light_castshadow.tolist() == [1]
    assert model.nmocap == 1 and model.light_bodyid[0] == model.body("sun").id
    # MuJoCo recentres a mesh: the raw compile poses the geom by the inverse of that move
    raw = mujoco.MjModel.from_xml_string(S.render_mjcf(B.BodyStyle(), 800, 600))
    assert np.linalg.norm(raw.geom_pos[geom]) > 1e-3 and np.allclose(raw.mesh_pos[mid], raw.geom_pos[geom])
    assert np.abs(raw.mesh_vert[adr:adr + len(mesh.positions)] - hml_to_world(mesh.positions)).max() > 1e-3


def test_camera_path_follows_root():
    root = np.zeros((40, 3))
    root[:, 0] = np.linspace(0, 2, 40)
    root[:, 2] = 0.9
    look = B.camera_path(root, 20.0)
    assert look.shape == (40, 3) and np.allclose(look[:, 2], B.BodyCamera().height)
    assert np.all(np.diff(look[:, 0]) >= 0) and abs(look[20, 0] - root[20, 0]) < 0.05


def test_extreme_points_give_the_fit_of_all_points():
    from simdiff.viz.camera import BodyCamera, extreme_points, fit_body_camera, point_boxes

    rng = np.random.default_rng(0)
    pts = rng.normal(size=(7, 50, 3)) + [0, 0, 1]
    look = np.zeros((7, 3))
    cam = BodyCamera()
    full = fit_body_camera([point_boxes(pts)], [look], cam, 4 / 3)
    few = fit_body_camera([point_boxes(extreme_points(pts, cam, 4 / 3))], [look], cam, 4 / 3)
    assert few[0] == full[0] and np.allclose(few[1][0], full[1][0])


# --------------------------------------------------------------------------------------
# framing: every vertex in the image
# --------------------------------------------------------------------------------------


def _mujoco_pixels(points: np.ndarray, lookats: np.ndarray, camera, size: tuple[int, int]) -> np.ndarray:
    """(T, N, 2) pixel (column, row) of world points (T, N, 3) through MuJoCo's own camera.

    Per frame ``mjv_updateScene`` places the free camera at the look-at point as
    :class:`BodyRenderer` does, and the points are projected with the eye position, axes and
    frustum MuJoCo hands to OpenGL: in mono rendering the average of the two stereo eyes of
    ``MjvScene.camera`` (``mjv_averageCamera``; each eye alone is ``ipd / 2`` to the side).
    """
    import mujoco

    model = S._copy_model(S._render_model(B.BodyStyle(), 640, 480))
    model.vis.global_.fovy = camera.fovy
    data = mujoco.MjData(model)
    scene = mujoco.MjvScene(model, maxgeom=16)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.azimuth, cam.elevation = camera.distance, camera.azimuth, camera.elevation
    w, h = size
    out = np.empty((*points.shape[:2], 2))
    for t, look in enumerate(lookats):
        cam.lookat[:] = look
        mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), mujoco.MjvPerturb(), cam,
                               mujoco.mjtCatBit.mjCAT_ALL.value, scene)
        gl = mujoco.mjv_averageCamera(scene.camera[0], scene.camera[1])
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


def _framing(motions, size):
    """Per panel the pixels (T, V, 2) of every body vertex through MuJoCo's camera, the clips and the camera."""
    clips, camera = B.body_view(motions, None, 20.0, size)
    return [_mujoco_pixels(c.posed()[0], c.lookat, camera, size) for c in clips], clips, camera


def _border(px: np.ndarray, size) -> float:
    """Smallest distance (px) of any point to the image border (negative: outside)."""
    w, h = size
    return float(min(px[..., 0].min(), w - px[..., 0].max(), px[..., 1].min(), h - px[..., 1].max()))


@pytest.mark.parametrize("name", ["jump 2.5 m", "walk", "long walk"])
def test_fitted_camera_keeps_every_vertex_in_view(name):
    motion = {"jump 2.5 m": lambda: hml.jump(80, height=2.5, airtime=1.4), "walk": lambda: hml.walk(60),
              "long walk": lambda: hml.walk(300, speed=1.5)}[name]()
    size = (320, 360)
    [px], _, camera = _framing([motion], size)
    margin_px = camera.margin * min(size) / 2
    assert _border(px, size) >= margin_px - 0.5, "a body vertex is outside the image or its margin"
    # the fit is tight: some vertex touches the margin (nothing is zoomed out for nothing)
    if camera.distance > camera.min_distance:
        tight = min(px[..., 1].min(), size[1] - px[..., 1].max()) / (size[1] / 2)
        side = min(px[..., 0].min(), size[0] - px[..., 0].max()) / (size[0] / 2)
        assert min(tight, side) == pytest.approx(camera.margin, abs=1e-3)
    if name == "jump 2.5 m":
        assert camera.distance > B.BodyCamera().distance  # a fixed default camera would crop the apex


def test_side_by_side_panels_share_one_camera():
    size = (320, 360)
    low, high = hml.jump(80, height=0.4, airtime=0.57), hml.jump(80, height=2.5, airtime=1.4)
    panels, _, camera = _framing([low, high], size)
    for px in panels:  # both fit in the shared camera
        assert _border(px, size) > 0
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


# --------------------------------------------------------------------------------------
# pixels
# --------------------------------------------------------------------------------------


def _body_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of the default (blue) body colour."""
    rgb = img.astype(int)
    return (rgb[..., 2] - rgb[..., 0] > 60) & (rgb[..., 2] > 120)


@pytest.fixture(scope="module", params=[0.0, 25.0], ids=["at the origin", "25 m away"])
def standing(backend, request):
    """A standing body rendered with shadows on and off (same camera), and its vertices' pixels; far from the
    origin the sun's shadow map only covers the body if the sun follows it."""
    camera = B.BodyCamera(distance=3.0, azimuth=120, elevation=-20, fit=False)
    joints = synthetic.standing(2) + np.array([request.param, 0.0, 0.0], dtype=np.float32)
    [clip], _ = B.body_view(joints, camera=camera)
    verts, normals = clip.posed(0, 1)
    lookat = (float(clip.lookat[0, 0]), float(clip.lookat[0, 1]), 0.85)
    images = []
    for shadows in (True, False):
        style = B.BodyStyle(shadows=shadows, multisample=0, captions=False)
        with B.BodyRenderer(W, H, style, camera, backend) as r:
            images.append(r.render(verts[0], normals[0], lookat))
    px = _mujoco_pixels(verts, np.array([lookat]), camera, (W, H))[0]
    return images, px


def test_standing_body_is_drawn_where_its_mesh_projects(standing):
    (on, _), px = standing
    assert on.shape == (H, W, 3) and on.dtype == np.uint8 and on.std() > 20
    body = _body_mask(on)
    assert body.sum() > 500
    from scipy.ndimage import binary_dilation

    near = binary_dilation(body, iterations=2)
    cols, rows = np.clip(np.round(px[:, 0]).astype(int), 0, W - 1), np.clip(np.round(px[:, 1]).astype(int), 0, H - 1)
    assert near[rows, cols].mean() > 0.97  # every projected vertex lands on the body ...
    rr, cc = np.nonzero(body)  # ... and the body spans what the vertices span
    assert abs(rr.min() - px[:, 1].min()) < 4 and abs(rr.max() - px[:, 1].max()) < 4
    assert abs(cc.min() - px[:, 0].min()) < 4 and abs(cc.max() - px[:, 0].max()) < 4
    # shaded, not one flat colour: the normals reach the lighting
    lum = on.astype(float).mean(-1)
    assert np.percentile(lum[body], 90) - np.percentile(lum[body], 10) > 30


def test_shadow_darkens_ground_next_to_body(standing):
    (on, off), _ = standing
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
    far = floor & ~shadow
    assert lum_on[shadow].mean() < np.percentile(lum_on[far], 5) - 60


def test_render_uses_the_shared_camera_for_every_panel(backend, monkeypatch):
    seen = []
    render = B.BodyRenderer.render

    def spy(self, vertices, normals, lookat, text="", text2=""):
        seen.append((self.cam.azimuth, self.cam.elevation, self.cam.distance, float(lookat[2])))
        return render(self, vertices, normals, lookat, text, text2)

    monkeypatch.setattr(B.BodyRenderer, "render", spy)
    motions = [hml.jump(12, height=0.4, start=2, airtime=0.4), hml.jump(12, height=2.5, start=2, airtime=0.4)]
    style = B.BodyStyle(multisample=0, shadow_size=256)
    frames = list(B.body_frames(motions, size=(48, 54), style=style))
    assert len(frames) == 12 and len(seen) == 24
    assert len(set(seen)) == 1  # one azimuth, elevation, distance and look-at height for all panels and frames
    _, camera = B.body_view(motions, None, 20.0, (48, 54))
    assert seen[0] == pytest.approx((camera.azimuth, camera.elevation, camera.distance, camera.height), abs=1e-5)


def test_rendered_high_jump_stays_inside_the_image(backend):
    """The real images agree with the projection: the body is whole in every frame, its top where predicted."""
    motion = hml.jump(40, height=2.5, start=5, airtime=1.4)
    size = (160, 180)
    [px], [clip], camera = _framing([motion], size)
    verts, normals = clip.posed()
    style = B.BodyStyle(multisample=0, shadows=False, captions=False)
    apex = int(np.argmax(clip.motion.root[:, 1]))
    with B.BodyRenderer(*size, style, camera) as r:
        for t in sorted({0, apex, len(clip) - 1, *range(0, len(clip), 6)}):
            body = _body_mask(r.render(verts[t], normals[t], clip.lookat[t]))
            rows, cols = np.nonzero(body)
            assert body.sum() > 150, t
            assert rows.min() > 2 and cols.min() > 2 and cols.max() < size[0] - 3 and rows.max() < size[1] - 3, t
            assert abs(rows.min() - px[t, :, 1].min()) < 3 and abs(rows.max() - px[t, :, 1].max()) < 3, t


# --------------------------------------------------------------------------------------
# files and errors
# --------------------------------------------------------------------------------------


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


@pytest.mark.parametrize("motion, needle", [
    (np.zeros((5, 21, 3)), r"motion 1: motion has shape \(5, 21, 3\), expected \(T, 22, 3\)"),
    (np.zeros((5, 76)), r"motion 1: motion has shape \(5, 76\)"),
    (np.full((5, 22, 3), np.nan), r"motion 1: .*NaN"),
])
def test_bad_motion_is_one_line(tmp_path, motion, needle):
    with pytest.raises(SimdiffError, match=needle) as err:
        B.render_body([synthetic.standing(4), motion], tmp_path / "x.mp4", progress=False)
    assert "\n" not in str(err.value)


def test_render_body_bad_options(tmp_path):
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
        S.gl_backend.__wrapped__()
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
