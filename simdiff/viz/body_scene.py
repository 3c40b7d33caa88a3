"""The render scene of :mod:`simdiff.viz.body`: its look (:class:`BodyStyle`), the render-only MJCF (floor,
lights, one mesh geom for the body) and :class:`BodyRenderer`, which poses the mesh and draws one image.

Every frame writes the posed vertices and normals (MuJoCo Z-up world, :func:`simdiff.sim.humanoid.hml_to_world`)
into ``model.mesh_vert`` / ``model.mesh_normal`` and uploads them with ``mjr_uploadMesh``. MuJoCo's compiler keeps
the mesh's vertex count and order (checked when the model is built) but moves the mesh into its inertial frame and
gives the geom the inverse pose; the geom pose is reset to the identity so vertices are written in world
coordinates. The sun hangs from a mocap body moved to the body's centre every frame, so its shadow map follows the
character.

Headless OpenGL: MuJoCo picks its GL backend from ``MUJOCO_GL`` when ``mujoco`` is first imported, and most
processes here import it for simulation before they render. So this module does not rely on that choice: it
creates the offscreen context itself with the backend :func:`simdiff.viz.gl.gl_backend` picks (``$MUJOCO_GL`` when
it is ``egl`` or ``osmesa``, else the first of EGL, OSMesa that works in a throw-away subprocess), and drives
MuJoCo's renderer (``MjvScene``, ``MjrContext``, ``mjr_render``, ``mjr_readPixels``) as ``mujoco.Renderer`` does.
"""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.body_mesh import BodyMesh, build_body
from simdiff.motion.skeleton import CANONICAL_OFFSETS
from simdiff.sim.humanoid import hml_to_world
from simdiff.viz._checks import positive_int
from simdiff.viz.camera import BodyCamera
from simdiff.viz.gl import _gl_context, gl_backend


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
        floor: the two checker colours of the floor (RGB); ``tile``: checker square side (m).
        sky: top and bottom colours of the gradient skybox.
        shadows: the sun casts shadows.
        shadow_size: shadow map resolution (pixels, square).
        shadow_reach: half-width of the square the sun's shadow map covers, in units of the
            model extent (:data:`EXTENT`); smaller is sharper, but floor points outside it get
            speckled (1.2 did, 2 does not).
        multisample: MSAA samples of the offscreen buffer (0 = off; 2 costs about 2× the
            CPU time of 0 with the software rasteriser).
        sun_dir: direction of the sun light (world, Z-up; need not be unit).
        reflectance: floor reflectance (0 = off; each reflection costs a render pass).
        captions: draw the caption and time in the top-left corner.
    """

    colors: tuple[tuple[float, float, float], ...] = PALETTE
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


EXTENT: float = 1.83
"""Model extent (m) MuJoCo scales the near/far clip planes and the sun's shadow map by: a standing body."""


# --------------------------------------------------------------------------------------
# the render model
# --------------------------------------------------------------------------------------


def _rgb(c: Sequence[float]) -> str:
    return " ".join(f"{float(x):.4g}" for x in c)


def _numbers(a: np.ndarray, fmt: str = "{:.6g}") -> str:
    return " ".join(fmt.format(x) for x in np.asarray(a).ravel())


@functools.lru_cache(maxsize=1)
def template_body() -> BodyMesh:
    """The body of HumanML3D's canonical skeleton, pelvis at the origin: the render model's mesh.

    Every skeleton gives a body with the same vertex count and triangles (:func:`build_body` fixes the
    tessellation), so one render model draws any motion's body.
    """
    return build_body(CANONICAL_OFFSETS)


def render_mjcf(style: BodyStyle = BodyStyle(), width: int = 640, height: int = 480) -> str:
    """The MJCF of the render scene (never used for simulation).

    A gradient skybox, a checkered floor plane, a dim headlight, a directional sun that casts shadows hung
    from a mocap body (``sun``) so it can follow the character, an offscreen buffer of at least ``width`` ×
    ``height`` pixels, and one mesh geom ``body`` (material ``skin``, no collisions) holding
    :func:`template_body` in MuJoCo's Z-up world.
    """
    mesh = template_body()
    root = ET.Element("mujoco", model="body render")
    ET.SubElement(root, "statistic", extent=f"{EXTENT:.4g}", center="0 0 0.85")
    visual = ET.SubElement(root, "visual")
    ET.SubElement(visual, "global", offwidth=str(max(int(width), 64)), offheight=str(max(int(height), 64)))
    ET.SubElement(visual, "quality", shadowsize=str(int(style.shadow_size)), offsamples=str(int(style.multisample)))
    ET.SubElement(visual, "headlight", ambient="0.32 0.32 0.32", diffuse="0.35 0.35 0.35", specular="0.05 0.05 0.05")
    ET.SubElement(visual, "map", znear="0.02", zfar="60", shadowclip=f"{style.shadow_reach:.3g}", haze="0.2")
    ET.SubElement(visual, "rgba", haze=_rgb((*style.sky[1], 1.0)))
    asset = ET.SubElement(root, "asset")
    ET.SubElement(asset, "texture", name="sky", type="skybox", builtin="gradient", rgb1=_rgb(style.sky[0]),
                  rgb2=_rgb(style.sky[1]), width="256", height="1536")
    ET.SubElement(asset, "texture", name="checker", type="2d", builtin="checker", rgb1=_rgb(style.floor[0]),
                  rgb2=_rgb(style.floor[1]), width="256", height="256", mark="edge",
                  markrgb=_rgb(np.array(style.floor[1]) * 0.9))
    ET.SubElement(asset, "material", name="floor", texture="checker", texuniform="true",
                  texrepeat=_rgb((1.0 / (2 * style.tile),) * 2), reflectance=f"{style.reflectance:.3g}")
    ET.SubElement(asset, "material", name="skin", rgba=_rgb((*style.colors[0], 1.0)), specular="0.3", shininess="0.4")
    ET.SubElement(asset, "mesh", name="body", vertex=_numbers(hml_to_world(mesh.positions)),
                  normal=_numbers(hml_to_world(mesh.normals)), face=_numbers(mesh.triangles, "{:d}"))
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 0.05", material="floor")
    ET.SubElement(world, "geom", name="body", type="mesh", mesh="body", material="skin", contype="0",
                  conaffinity="0", group="1")
    sun = np.asarray(style.sun_dir, dtype=float)
    sun = sun / np.linalg.norm(sun)
    holder = ET.SubElement(world, "body", name="sun", mocap="true", pos="0 0 0.9")
    ET.SubElement(holder, "light", name="sun", directional="true", castshadow="true", pos=_rgb(-4.0 * sun),
                  dir=_rgb(sun), diffuse="0.75 0.75 0.72", specular="0.25 0.25 0.25", ambient="0.12 0.12 0.12")
    return ET.tostring(root, encoding="unicode")


@functools.lru_cache(maxsize=4)
def _render_model(style: BodyStyle, width: int, height: int):
    """The compiled :func:`render_mjcf` with the body geom at the world origin, its mesh checked.

    MuJoCo's compiler moves a mesh into its inertial frame (``mesh_pos``, ``mesh_quat``) and poses the geom by
    the inverse; here the geom pose is reset to the identity and ``mesh_vert`` / ``mesh_normal`` are set back
    to the template in world coordinates. It keeps the vertex count
    and order, which the per-frame writes rely on: a compiler that changed them raises.
    """
    import mujoco

    model = mujoco.MjModel.from_xml_string(render_mjcf(style, width, height))
    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "body")
    mesh_id = int(model.geom_dataid[geom])
    rot = np.empty(9)
    mujoco.mju_quat2Mat(rot, model.geom_quat[geom])
    adr, num = model.mesh_vertadr[mesh_id], model.mesh_vertnum[mesh_id]
    world = model.mesh_vert[adr:adr + num] @ rot.reshape(3, 3).T + model.geom_pos[geom]
    expected = hml_to_world(template_body().positions)
    faces = slice(model.mesh_faceadr[mesh_id], model.mesh_faceadr[mesh_id] + model.mesh_facenum[mesh_id])
    if num != len(expected) or model.mesh_normalnum[mesh_id] != len(expected) \
            or not np.array_equal(model.mesh_face[faces], template_body().triangles) \
            or not np.array_equal(model.mesh_facenormal[faces], model.mesh_face[faces]) \
            or np.abs(world - expected).max() > 1e-4:
        raise SimdiffError(f"MuJoCo {mujoco.__version__} changed the body mesh ({num} vertices kept of "
                           f"{len(expected)}); per-frame vertex updates need them in order")
    model.geom_pos[geom] = 0.0
    model.geom_quat[geom] = (1.0, 0.0, 0.0, 0.0)
    model.mesh_vert[adr:adr + num] = expected
    nadr = model.mesh_normaladr[mesh_id]
    model.mesh_normal[nadr:nadr + num] = hml_to_world(template_body().normals)
    return model


class BodyRenderer:
    """Offscreen renderer of the skinned body: one ``width`` × ``height`` image per call.

    Use as a context manager (or call :meth:`close`) so the GL context is freed::

        with BodyRenderer(640, 480) as r:
            image = r.render(vertices, normals, lookat=(0, 0, 0.9))

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
        # a private copy: colours and mesh vertices change per frame
        self.model = _copy_model(_render_model(style, max(self.width, 640), max(self.height, 480)))
        self.data = mujoco.MjData(self.model)
        self._ctx = _gl_context(backend, self.width, self.height)
        self._con = mujoco.MjrContext(self.model, mujoco.mjtFontScale.mjFONTSCALE_150.value)
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN.value, self._con)
        # a farther or wider view sees more floor: widen the sun's shadow map with it (floor outside is speckled)
        reach = camera.distance * max(1.0, self.width / self.height) / BodyCamera.distance
        self._con.shadowClip = float(self._con.shadowClip * max(1.0, reach))
        self.scene = mujoco.MjvScene(self.model, maxgeom=16)
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
        self._mesh = int(self.model.geom_dataid[mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "body")])
        adr, num = self.model.mesh_vertadr[self._mesh], self.model.mesh_vertnum[self._mesh]
        nadr = self.model.mesh_normaladr[self._mesh]
        self._verts = self.model.mesh_vert[adr:adr + num]  # views into the model's arrays
        self._normals = self.model.mesh_normal[nadr:nadr + num]
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

    def render(self, vertices: np.ndarray, normals: np.ndarray, lookat: Sequence[float], text: str = "",
               text2: str = "") -> np.ndarray:
        """(H, W, 3) uint8 image of the body posed at ``vertices`` with unit ``normals``, camera at ``lookat``.

        ``vertices`` and ``normals`` are (V, 3) in MuJoCo's Z-up world (metres), in the order of
        :func:`template_body`; the sun follows their centre. ``text`` (left column) and ``text2`` (right column)
        are overlaid in the top-left corner.
        """
        mj = self.mj
        if self._con is None:
            raise SimdiffError("BodyRenderer.render called after close()")
        if np.shape(vertices) != self._verts.shape or np.shape(normals) != self._normals.shape:
            raise SimdiffError(f"BodyRenderer.render needs {self._verts.shape} vertices and normals, "
                               f"got {np.shape(vertices)} and {np.shape(normals)}")
        self._ctx.make_current()
        self._verts[:] = vertices
        self._normals[:] = normals
        mj.mjr_uploadMesh(self.model, self._con, self._mesh)
        self.data.mocap_pos[0] = self._verts.mean(axis=0)
        mj.mj_kinematics(self.model, self.data)
        mj.mj_camlight(self.model, self.data)
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
