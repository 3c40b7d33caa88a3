"""Body renders of motions with MuJoCo's offscreen OpenGL renderer: MP4, GIF or PNG filmstrip.

A motion is either HumanML3D joints ``(T, 22, 3)`` (Y-up metres, 20 fps), turned into
humanoid states with the simulator's IK (:func:`simdiff.sim.retarget.ik_sequence`), or
humanoid states ``(T, nq)`` (a rollout's qpos sampled at the frame rate) used as they are.
Each frame sets qpos, runs ``mj_forward`` and renders the humanoid of
:mod:`simdiff.sim.humanoid` on a checkered floor under a shadow-casting sun, seen by a
camera that follows the smoothed root horizontally. Side-by-side panels share one camera
(azimuth, elevation, distance, look-at height), fitted to the whole render so that every geom
and joint of every frame stays in the image (:func:`body_view`,
:func:`simdiff.viz.camera.fit_body_camera`).

The visual extras (skybox, floor texture, materials, lights, offscreen buffer size) are added
to a copy of the simulation MJCF by :func:`render_mjcf`; the simulation model is unchanged
and the render model has the same bodies and joints, so qpos carries over.

Headless OpenGL: MuJoCo picks its GL backend from ``MUJOCO_GL`` when ``mujoco`` is first
imported, and most processes here import it for simulation before they render. So this
module does not rely on that choice: it creates the offscreen context itself with the
backend :func:`simdiff.viz.gl.gl_backend` picks (``$MUJOCO_GL`` when it is ``egl`` or ``osmesa``,
else the first of EGL, OSMesa that works in a throw-away subprocess), and drives MuJoCo's renderer
(``MjvScene``, ``MjrContext``, ``mjr_render``, ``mjr_readPixels``) as ``mujoco.Renderer``
does.
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterator, Sequence

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import atomic_path
from simdiff.motion.skeleton import FPS, NUM_JOINTS
from simdiff.viz._checks import ANIMATION_SUFFIXES, as_captions, output_path, positive_float, positive_int
from simdiff.viz.camera import BodyCamera, camera_path, fit_body_camera, geom_boxes, join_boxes, point_boxes
from simdiff.viz.gl import _gl_context, gl_backend
from simdiff.viz.video import write_video


BODY_SUFFIXES: tuple[str, ...] = (*ANIMATION_SUFFIXES, ".png")
"""Outputs of :func:`render_body`: ``.mp4`` / ``.gif`` animations or a ``.png`` filmstrip."""

PALETTE: tuple[tuple[float, float, float], ...] = (
    (0.32, 0.56, 0.86),  # blue
    (0.93, 0.55, 0.24),  # orange
    (0.35, 0.72, 0.45),  # green
    (0.70, 0.45, 0.80),  # purple
)
"""Body colours (RGB in [0, 1]) of side-by-side panels, in order."""

@dataclass(frozen=True)
class BodyStyle:
    """Look of a body render.

    Attributes:
        colors: body colour per panel (RGB in [0, 1]), cycled.
        shoe: colour of the feet and toes.
        floor: the two checker colours of the floor (RGB); ``tile``: checker square side (m).
        sky: top and bottom colours of the gradient skybox.
        shadows: the sun casts shadows.
        shadow_size: shadow map resolution (pixels, square).
        shadow_reach: half-width of the square the sun's shadow map covers, in units of the
            model extent (about 1.8 m); smaller is sharper, but floor points outside it get
            speckled (1.2 did, 2 does not).
        multisample: MSAA samples of the offscreen buffer (0 = off; 2 costs about 2× the
            CPU time of 0 with the software rasteriser).
        sun_dir: direction of the sun light (world, Z-up; need not be unit).
        reflectance: floor reflectance (0 = off; each reflection costs a render pass).
        captions: draw the caption and time in the top-left corner.
    """

    colors: tuple[tuple[float, float, float], ...] = PALETTE
    shoe: tuple[float, float, float] = (0.22, 0.22, 0.25)
    floor: tuple[tuple[float, float, float], tuple[float, float, float]] = ((0.80, 0.80, 0.78), (0.62, 0.63, 0.64))
    tile: float = 0.5
    sky: tuple[tuple[float, float, float], tuple[float, float, float]] = ((0.55, 0.70, 0.88), (0.95, 0.96, 0.98))
    shadows: bool = True
    shadow_size: int = 2048
    shadow_reach: float = 2.0
    multisample: int = 2
    sun_dir: tuple[float, float, float] = (0.35, 0.45, -1.0)
    reflectance: float = 0.0
    captions: bool = True


# --------------------------------------------------------------------------------------
# the render model
# --------------------------------------------------------------------------------------


def _rgb(c: Sequence[float]) -> str:
    return " ".join(f"{float(x):.4g}" for x in c)


def render_mjcf(cfg=None, style: BodyStyle = BodyStyle(), width: int = 640, height: int = 480) -> str:
    """The humanoid MJCF with visual extras for rendering (never used for simulation).

    Adds a gradient skybox, a checkered floor material, body/shoe materials, a headlight
    kept dim, a directional sun that follows the character's centre of mass and casts
    shadows, and an offscreen buffer of at least ``width`` × ``height`` pixels. Bodies,
    joints and geoms are those of :func:`simdiff.sim.humanoid.build_mjcf`.

    Args:
        cfg: :class:`simdiff.sim.humanoid.HumanoidConfig` (default config when None).
    """
    from simdiff.sim.humanoid import HumanoidConfig, build_mjcf

    root = ET.fromstring(build_mjcf(cfg if cfg is not None else HumanoidConfig()))
    visual = ET.Element("visual")
    ET.SubElement(visual, "global", offwidth=str(max(int(width), 64)), offheight=str(max(int(height), 64)))
    ET.SubElement(visual, "quality", shadowsize=str(int(style.shadow_size)), offsamples=str(int(style.multisample)))
    ET.SubElement(visual, "headlight", ambient="0.32 0.32 0.32", diffuse="0.35 0.35 0.35", specular="0.05 0.05 0.05")
    ET.SubElement(visual, "map", znear="0.02", zfar="60", shadowclip=f"{style.shadow_reach:.3g}", haze="0.2")
    ET.SubElement(visual, "rgba", haze=_rgb((*style.sky[1], 1.0)))
    asset = ET.Element("asset")
    ET.SubElement(asset, "texture", name="sky", type="skybox", builtin="gradient", rgb1=_rgb(style.sky[0]),
                  rgb2=_rgb(style.sky[1]), width="256", height="1536")
    ET.SubElement(asset, "texture", name="checker", type="2d", builtin="checker", rgb1=_rgb(style.floor[0]),
                  rgb2=_rgb(style.floor[1]), width="256", height="256", mark="edge",
                  markrgb=_rgb(np.array(style.floor[1]) * 0.9))
    ET.SubElement(asset, "material", name="floor", texture="checker", texuniform="true",
                  texrepeat=_rgb((1.0 / (2 * style.tile),) * 2), reflectance=f"{style.reflectance:.3g}")
    ET.SubElement(asset, "material", name="skin", rgba=_rgb((*style.colors[0], 1.0)), specular="0.3", shininess="0.4")
    ET.SubElement(asset, "material", name="shoe", rgba=_rgb((*style.shoe, 1.0)), specular="0.1", shininess="0.2")
    # <visual> and <asset> go right after <compiler>/<option>/<size>, before <default>
    at = list(root).index(root.find("default"))
    root.insert(at, asset)
    root.insert(at, visual)
    for default in root.iter("default"):
        cls = default.get("class")
        geom = default.find("geom")
        if cls in ("body", "hand", "foot"):
            if geom is None:
                geom = ET.SubElement(default, "geom")
            geom.attrib.pop("rgba", None)
            geom.set("material", "shoe" if cls == "foot" else "skin")
    world = root.find("worldbody")
    for light in world.findall("light"):
        world.remove(light)
    sun = np.asarray(style.sun_dir, dtype=float)
    sun = sun / np.linalg.norm(sun)
    ET.SubElement(world, "light", name="sun", mode="trackcom", directional="true",
                  castshadow="true", pos=_rgb(-4.0 * sun), dir=_rgb(sun),
                  diffuse="0.75 0.75 0.72", specular="0.25 0.25 0.25", ambient="0.12 0.12 0.12")
    floor = world.find("geom[@name='floor']")
    floor.attrib.pop("rgba", None)
    floor.set("material", "floor")
    floor.set("size", "0 0 0.05")
    return ET.tostring(root, encoding="unicode")


@functools.lru_cache(maxsize=4)
def _render_model(style: BodyStyle, width: int, height: int):
    import mujoco

    return mujoco.MjModel.from_xml_string(render_mjcf(None, style, width, height))


# --------------------------------------------------------------------------------------
# motions → qpos
# --------------------------------------------------------------------------------------


def motion_qpos(motion: np.ndarray, model=None) -> np.ndarray:
    """Humanoid states (T, nq) float64 of a motion.

    Args:
        motion: (T, 22, 3) HumanML3D joints (Y-up metres), converted with the simulator's
            IK (closed form + Gauss-Newton polish, :func:`simdiff.sim.retarget.ik_sequence`;
            no ground alignment, smoothing or resampling, so the render shows the motion as
            it is), or (T, nq) humanoid states used unchanged.
        model: the simulation humanoid (default :func:`simdiff.sim.humanoid.load_model`).
    Raises:
        SimdiffError: any other shape, or non-finite values.
    """
    from simdiff.sim.retarget import RetargetConfig, ik_sequence
    from simdiff.sim.humanoid import hml_to_world, load_model

    model = model if model is not None else load_model()
    if hasattr(motion, "detach"):
        motion = motion.detach().cpu().numpy()
    arr = np.asarray(motion, dtype=np.float64)
    if arr.ndim == 2 and arr.shape[1] == model.nq and arr.shape[0] >= 1:
        q = arr.copy()
    elif arr.ndim == 3 and arr.shape[1:] == (NUM_JOINTS, 3) and arr.shape[0] >= 1:
        if not np.isfinite(arr).all():
            raise SimdiffError("motion contains NaN or infinite joint positions")
        q, _ = ik_sequence(model, hml_to_world(arr), RetargetConfig())
    else:
        raise SimdiffError(f"motion has shape {tuple(arr.shape)}, expected (T, {NUM_JOINTS}, 3) joints "
                           f"or (T, {model.nq}) humanoid qpos")
    if not np.isfinite(q).all():
        raise SimdiffError("motion contains NaN or infinite values")
    return q


# --------------------------------------------------------------------------------------
# the renderer
# --------------------------------------------------------------------------------------


class BodyRenderer:
    """Offscreen renderer of the humanoid: one ``width`` × ``height`` image per call.

    Use as a context manager (or call :meth:`close`) so the GL context is freed::

        with BodyRenderer(640, 480) as r:
            image = r.render(qpos, lookat=(0, 0, 0.9))

    Args:
        width, height: image size in pixels.
        style: :class:`BodyStyle`; camera: :class:`BodyCamera` (distance, angles, fov) used as
            given by every render of this renderer (no fitting here: see :func:`body_view`).
        backend: ``"egl"`` / ``"osmesa"``; default :func:`gl_backend`.
    """

    def __init__(self, width: int = 640, height: int = 480, style: BodyStyle = BodyStyle(),
                 camera: BodyCamera = BodyCamera(), backend: str | None = None) -> None:
        import mujoco

        self.width = positive_int(width, "width")
        self.height = positive_int(height, "height")
        self.style = style
        self.camera = camera
        self.mj = mujoco
        self._ctx = None
        self._con = None
        backend = backend or gl_backend()
        # a private copy: colours are changed per panel
        self.model = _copy_model(_render_model(style, max(self.width, 640), max(self.height, 480)))
        self.data = mujoco.MjData(self.model)
        self._ctx = _gl_context(backend, self.width, self.height)
        self._con = mujoco.MjrContext(self.model, mujoco.mjtFontScale.mjFONTSCALE_150.value)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN.value, self._con)
        # a farther or wider view sees more floor: widen the sun's shadow map with it (floor outside is speckled)
        reach = camera.distance * max(1.0, self.width / self.height) / BodyCamera.distance
        self._con.shadowClip = float(self._con.shadowClip * max(1.0, reach))
        self.scene = mujoco.MjvScene(self.model, maxgeom=500)
        self.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = bool(style.shadows)
        self.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = style.reflectance > 0
        self.scene.flags[mujoco.mjtRndFlag.mjRND_SKYBOX] = True
        self.option = mujoco.MjvOption()
        self.perturb = mujoco.MjvPerturb()
        self.cam = mujoco.MjvCamera()
        self.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.cam.distance = camera.distance
        self.cam.azimuth = camera.azimuth
        self.cam.elevation = camera.elevation
        self.model.vis.global_.fovy = camera.fovy
        self.viewport = mujoco.MjrRect(0, 0, self.width, self.height)
        self._skin = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_MATERIAL, "skin")
        self._buffer = np.empty((self.height, self.width, 3), dtype=np.uint8)

    def __enter__(self) -> "BodyRenderer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Free the MuJoCo and GL contexts (safe to call twice)."""
        if self._con is not None:
            self._ctx.make_current()
            self._con.free()
            self._con = None
        if self._ctx is not None:
            self._ctx.free()
            self._ctx = None

    def __del__(self) -> None:  # pragma: no cover - best effort at interpreter exit
        try:
            self.close()
        except Exception:
            pass

    def set_color(self, rgb: Sequence[float]) -> None:
        """Body colour (RGB in [0, 1]) of the following renders."""
        self.model.mat_rgba[self._skin, :3] = np.asarray(rgb, dtype=np.float32)

    def render(self, qpos: np.ndarray, lookat: Sequence[float], text: str = "", text2: str = "") -> np.ndarray:
        """(H, W, 3) uint8 image of the humanoid in state ``qpos`` (nq,), camera at ``lookat``.

        ``text`` (left column) and ``text2`` (right column) are overlaid in the top-left corner.
        """
        mj = self.mj
        if self._con is None:
            raise SimdiffError("BodyRenderer.render called after close()")
        self._ctx.make_current()
        self.data.qpos[:] = qpos
        self.data.qvel[:] = 0.0
        mj.mj_forward(self.model, self.data)
        self.cam.lookat[:] = lookat
        mj.mjv_updateScene(self.model, self.data, self.option, self.perturb, self.cam,
                           mj.mjtCatBit.mjCAT_ALL.value, self.scene)
        mj.mjr_render(self.viewport, self.scene, self._con)
        if not text:  # a lone second column would leave an empty box on the left
            text, text2 = text2, ""
        if self.style.captions and text:
            mj.mjr_overlay(mj.mjtFont.mjFONT_NORMAL.value, mj.mjtGridPos.mjGRID_TOPLEFT.value, self.viewport,
                           text, text2, self._con)
        mj.mjr_readPixels(self._buffer, None, self.viewport, self._con)
        return np.flipud(self._buffer).copy()


def _copy_model(model):
    import copy

    return copy.copy(model)


# --------------------------------------------------------------------------------------
# animations and filmstrips
# --------------------------------------------------------------------------------------


@dataclass
class _Clip:
    qpos: np.ndarray
    lookat: np.ndarray
    caption: str
    color: tuple[float, float, float]


def body_view(motions, captions=None, fps: float = FPS, size: tuple[int, int] = (640, 480),
              style: BodyStyle = BodyStyle(), camera: BodyCamera = BodyCamera()) -> tuple[list[_Clip], BodyCamera]:
    """The panels of a render and the one camera they share.

    Every panel is seen with the same azimuth, elevation, distance and look-at height (so
    sizes and heights compare across panels); only the horizontal look-at point follows each
    panel's own smoothed root. With ``camera.fit`` the distance and look-at height are those of
    :func:`simdiff.viz.camera.fit_body_camera`: every geom of every frame of every panel lies
    inside the ``size`` image with ``camera.margin`` to spare.

    Returns:
        (clips, camera): per motion its qpos (T, nq), look-at path (T, 3), caption and colour;
        and the camera used.
    """
    from simdiff.sim.humanoid import load_model

    if isinstance(motions, np.ndarray) or hasattr(motions, "detach"):
        motions = [motions]
    motions = list(motions)
    if not motions:
        raise SimdiffError("motions is an empty list; give at least one (T, 22, 3) or (T, nq) array")
    captions = as_captions(captions, len(motions))
    model = load_model()
    qs = []
    for i, m in enumerate(motions):
        try:
            qs.append(motion_qpos(m, model))
        except SimdiffError as exc:
            raise SimdiffError(f"motion {i}: {exc}") from None
    if camera.fit:  # the humanoid's geoms and, for joint motions, the joints themselves stay in view
        from simdiff.sim.humanoid import hml_to_world

        camera = replace(camera, follow_height=False)
        paths = [camera_path(q, fps, camera) for q in qs]
        boxes = [geom_boxes(model, q) for q in qs]
        for i, m in enumerate(motions):
            m = np.asarray(m.detach().cpu().numpy() if hasattr(m, "detach") else m, dtype=np.float64)
            if m.ndim == 3:
                boxes[i] = join_boxes(boxes[i], point_boxes(hml_to_world(m)))
        camera, shifts = fit_body_camera(boxes, paths, camera, size[0] / size[1])
    else:
        shifts = [np.zeros(3)] * len(qs)
    out = []
    for i, (q, c, s) in enumerate(zip(qs, captions, shifts)):
        out.append(_Clip(q, camera_path(q, fps, camera) + s, c, style.colors[i % len(style.colors)]))
    return out, camera


def _panel(renderer: BodyRenderer, clip: _Clip, t: int, fps: float) -> np.ndarray:
    i = min(t, len(clip.qpos) - 1)
    renderer.set_color(clip.color)
    clock = f"{i / fps:.2f} s" + (" (end)" if t > i else "")
    return renderer.render(clip.qpos[i], clip.lookat[i], clip.caption, clock)


def body_frames(motions, captions: Sequence[str] | None = None, fps: float = FPS, size: tuple[int, int] = (640, 480),
                style: BodyStyle = BodyStyle(), camera: BodyCamera = BodyCamera(),
                progress: bool = False) -> Iterator[np.ndarray]:
    """Yield the (H, W·n, 3) uint8 frames of motions rendered side by side.

    Args:
        motions: one or a list of (T, 22, 3) joints or (T, nq) humanoid states at ``fps``;
            shorter clips hold their last frame.
        captions: one per motion (shown top-left), or None.
        fps: frame rate of the motions (frames per second), for the clock and the camera.
        size: (width, height) in pixels of one panel.
        progress: show a tqdm bar on stderr.
    """
    fps = positive_float(fps, "fps")
    clips, camera = body_view(motions, captions, fps, size, style, camera)
    n = max(len(c.qpos) for c in clips)
    from tqdm.auto import tqdm

    with BodyRenderer(size[0], size[1], style, camera) as renderer:
        for t in tqdm(range(n), desc="render", unit="frame", disable=not progress, leave=False, dynamic_ncols=True):
            yield np.concatenate([_panel(renderer, c, t, fps) for c in clips], axis=1)


def render_body(motions, path: str | Path, captions: Sequence[str] | None = None, fps: float = FPS,
                size: tuple[int, int] | None = None, n_frames: int = 8, style: BodyStyle = BodyStyle(),
                camera: BodyCamera = BodyCamera(), progress: bool = True) -> Path:
    """Render motions with the MuJoCo humanoid to an MP4, a GIF or a PNG filmstrip.

    Args:
        motions: one or a list of (T, 22, 3) HumanML3D joints (Y-up metres) or (T, nq)
            humanoid qpos, at ``fps``; side by side in an animation, one row each in a filmstrip.
        path: ``.mp4`` (H.264), ``.gif`` or ``.png`` (filmstrip); parent folders are created.
        captions: one per motion, or None.
        fps: frame rate of the motions and of the video (HumanML3D: 20).
        size: (width, height) of one panel in pixels; default 640×480 for videos and 320×360
            for filmstrip cells.
        n_frames: filmstrip frames per row (evenly spaced, first and last included).
        progress: tqdm bar on stderr.
    Returns:
        The written path.
    Raises:
        SimdiffError: bad motion shape, suffix or value, or no headless OpenGL.
    """
    path = output_path(path, BODY_SUFFIXES)
    fps = positive_float(fps, "fps")
    if path.suffix.lower() == ".png":
        cell = (320, 360) if size is None else size
        _check_size(cell)
        image = body_filmstrip(motions, captions, fps, cell, n_frames, style, camera, progress)
        from PIL import Image

        with atomic_path(path) as tmp:
            Image.fromarray(image).save(tmp, format="PNG")
        return path
    size = (640, 480) if size is None else size
    _check_size(size)
    write_video(body_frames(motions, captions, fps, size, style, camera, progress), path, fps)
    return path


def body_filmstrip(motions, captions: Sequence[str] | None = None, fps: float = FPS, size: tuple[int, int] = (320, 360),
                   n_frames: int = 8, style: BodyStyle = BodyStyle(), camera: BodyCamera = BodyCamera(),
                   progress: bool = False) -> np.ndarray:
    """(rows·H, n_frames·W, 3) uint8 grid: one row per motion, ``n_frames`` evenly spaced frames."""
    fps = positive_float(fps, "fps")
    n_frames = positive_int(n_frames, "n_frames")
    clips, camera = body_view(motions, captions, fps, size, style, camera)
    from tqdm.auto import tqdm

    rows = []
    with BodyRenderer(size[0], size[1], style, camera) as renderer:
        bar = tqdm(total=len(clips) * n_frames, desc="render", unit="frame", disable=not progress, leave=False,
                   dynamic_ncols=True)
        for clip in clips:
            cells = []
            renderer.set_color(clip.color)
            idx = np.round(np.linspace(0, len(clip.qpos) - 1, n_frames)).astype(int)
            for k, t in enumerate(idx):
                text = clip.caption if k == 0 else ""
                cells.append(renderer.render(clip.qpos[t], clip.lookat[t], text, f"{t / fps:.2f} s"))
                bar.update()
            rows.append(np.concatenate(cells, axis=1))
        bar.close()
    return np.concatenate(rows, axis=0)


def _check_size(size: Sequence[int]) -> None:
    if len(size) != 2:
        raise SimdiffError(f"size must be (width, height) in pixels, got {tuple(size)!r}")
    for v, name in zip(size, ("width", "height")):
        positive_int(v, name)
        if v < 16 or v > 4096:
            raise SimdiffError(f"{name} must be in [16, 4096] pixels, got {v}")
