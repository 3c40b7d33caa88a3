"""Body renders of motions with MuJoCo's offscreen OpenGL renderer: MP4, GIF or PNG filmstrip.

A motion is HumanML3D joints ``(T, 22, 3)`` (Y-up metres, 20 fps). It is fitted with rotations on its own
skeleton (:func:`simdiff.motion.rigid.fit` with the motion's mean bone lengths) and drawn as the project's
skinned body (:func:`simdiff.motion.body_mesh.build_body`, posed by :func:`simdiff.motion.body_mesh.skin`
exactly as the glTF export poses it), on a checkered floor under a shadow-casting sun, seen by a camera that
follows the smoothed pelvis horizontally. Side-by-side panels share one camera (azimuth, elevation, distance,
look-at height), fitted to the whole render so that every body vertex of every frame stays in the image
(:func:`body_view`, :func:`simdiff.viz.camera.fit_body_camera`).

The scene, the mesh upload and the offscreen OpenGL context are :mod:`simdiff.viz.body_scene`'s.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterator, Sequence

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import atomic_path
from simdiff.motion.body_mesh import BodyMesh, build_body, skin
from simdiff.motion.rigid import RigidMotion, fit
from simdiff.motion.skeleton import FPS, NUM_JOINTS
from simdiff.sim.humanoid import hml_to_world
from simdiff.viz._checks import ANIMATION_SUFFIXES, as_captions, output_path, positive_float, positive_int
from simdiff.viz.body_scene import BodyRenderer, BodyStyle
from simdiff.viz.camera import BodyCamera, camera_path, extreme_points, fit_body_camera, point_boxes
from simdiff.viz.video import write_video


BODY_SUFFIXES: tuple[str, ...] = (*ANIMATION_SUFFIXES, ".png")
"""Outputs of :func:`render_body`: ``.mp4`` / ``.gif`` animations or a ``.png`` filmstrip."""

# --------------------------------------------------------------------------------------
# motions → posed bodies
# --------------------------------------------------------------------------------------


@dataclass
class BodyClip:
    """One panel: the fitted motion, its body and how it is shown.

    Attributes:
        motion: rotations on the motion's own skeleton (:func:`simdiff.motion.rigid.fit`), Y up.
        mesh: :func:`build_body` of ``motion.offsets`` with the pelvis at ``motion.root[0]``.
        lookat: (T, 3) world (Z-up) look-at path of the camera.
        caption: text shown top-left; color: body colour (RGB in [0, 1]).
    """

    motion: RigidMotion
    mesh: BodyMesh
    lookat: np.ndarray
    caption: str
    color: tuple[float, float, float]

    def __len__(self) -> int:
        return len(self.motion.root)

    def posed(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """World (Z-up) vertices and unit normals (t, V, 3) float32 of frames ``start:stop``."""
        part = RigidMotion(self.motion.local[start:stop], self.motion.root[start:stop], self.motion.offsets)
        verts, normals = skin(self.mesh, part, self.motion.root[0])
        return hml_to_world(verts), hml_to_world(normals)


def fit_motion(motion) -> tuple[RigidMotion, BodyMesh]:
    """The rigid fit of (T, 22, 3) joints on their own skeleton and its body (pelvis at the first frame's).

    Raises:
        SimdiffError: another shape, or non-finite values.
    """
    if hasattr(motion, "detach"):
        motion = motion.detach().cpu().numpy()
    arr = np.asarray(motion, dtype=np.float64)
    if arr.ndim != 3 or arr.shape[1:] != (NUM_JOINTS, 3) or arr.shape[0] < 1:
        raise SimdiffError(f"motion has shape {tuple(arr.shape)}, expected (T, {NUM_JOINTS}, 3) joints")
    if not np.isfinite(arr).all():
        raise SimdiffError("motion contains NaN or infinite joint positions")
    rigid = fit(arr, None)
    return rigid, build_body(rigid.offsets, rigid.root[0])


def _extremes(clip: BodyClip, camera: BodyCamera, aspect: float, chunk: int = 64) -> np.ndarray:
    """(T, 4, 3) the world vertices of each frame that bound the view (:func:`extreme_points`)."""
    parts = [extreme_points(clip.posed(a, a + chunk)[0], camera, aspect) for a in range(0, len(clip), chunk)]
    return np.concatenate(parts)


# --------------------------------------------------------------------------------------
# animations and filmstrips
# --------------------------------------------------------------------------------------


def body_view(motions, captions=None, fps: float = FPS, size: tuple[int, int] = (640, 480),
              style: BodyStyle = BodyStyle(), camera: BodyCamera = BodyCamera()) -> tuple[list[BodyClip], BodyCamera]:
    """The panels of a render and the one camera they share.

    Every panel is seen with the same azimuth, elevation, distance and look-at height (so
    sizes and heights compare across panels); only the horizontal look-at point follows each
    panel's own smoothed pelvis. With ``camera.fit`` the distance and look-at height are those of
    :func:`simdiff.viz.camera.fit_body_camera`: every body vertex of every frame of every panel lies
    inside the ``size`` image with ``camera.margin`` to spare.

    Args:
        motions: one or a list of (T, 22, 3) HumanML3D joints (Y-up metres).
    Returns:
        (clips, camera): per motion a :class:`BodyClip`; and the camera used.
    Raises:
        SimdiffError: one line naming the motion with a bad shape or value.
    """
    if isinstance(motions, np.ndarray) or hasattr(motions, "detach"):
        motions = [motions]
    motions = list(motions)
    if not motions:
        raise SimdiffError("motions is an empty list; give at least one (T, 22, 3) array")
    captions = as_captions(captions, len(motions))
    clips = []
    for i, (m, c) in enumerate(zip(motions, captions)):
        try:
            rigid, mesh = fit_motion(m)
        except SimdiffError as exc:
            raise SimdiffError(f"motion {i}: {exc}") from None
        clips.append(BodyClip(rigid, mesh, np.zeros((len(rigid.root), 3)), c, style.colors[i % len(style.colors)]))
    roots = [hml_to_world(c.motion.root) for c in clips]
    if camera.fit:
        camera = replace(camera, follow_height=False)
        aspect = size[0] / size[1]
        boxes = [point_boxes(_extremes(c, camera, aspect)) for c in clips]
        camera, shifts = fit_body_camera(boxes, [camera_path(r, fps, camera) for r in roots], camera, aspect)
    else:
        shifts = [np.zeros(3)] * len(clips)
    for c, r, s in zip(clips, roots, shifts):
        c.lookat = camera_path(r, fps, camera) + s
    return clips, camera


def _panel(renderer: BodyRenderer, clip: BodyClip, t: int, fps: float) -> np.ndarray:
    i = min(t, len(clip) - 1)
    renderer.set_color(clip.color)
    clock = f"{i / fps:.2f} s" + (" (end)" if t > i else "")
    verts, normals = clip.posed(i, i + 1)
    return renderer.render(verts[0], normals[0], clip.lookat[i], clip.caption, clock)


def body_frames(motions, captions: Sequence[str] | None = None, fps: float = FPS, size: tuple[int, int] = (640, 480),
                style: BodyStyle = BodyStyle(), camera: BodyCamera = BodyCamera(),
                progress: bool = False) -> Iterator[np.ndarray]:
    """Yield the (H, W·n, 3) uint8 frames of motions rendered side by side.

    Args:
        motions: one or a list of (T, 22, 3) joints at ``fps``; shorter clips hold their last frame.
        captions: one per motion (shown top-left), or None.
        fps: frame rate of the motions (frames per second), for the clock and the camera.
        size: (width, height) in pixels of one panel.
        progress: show a tqdm bar on stderr.
    """
    fps = positive_float(fps, "fps")
    clips, camera = body_view(motions, captions, fps, size, style, camera)
    n = max(len(c) for c in clips)
    from tqdm.auto import tqdm

    with BodyRenderer(size[0], size[1], style, camera) as renderer:
        for t in tqdm(range(n), desc="render", unit="frame", disable=not progress, leave=False, dynamic_ncols=True):
            yield np.concatenate([_panel(renderer, c, t, fps) for c in clips], axis=1)


def render_body(motions, path: str | Path, captions: Sequence[str] | None = None, fps: float = FPS,
                size: tuple[int, int] | None = None, n_frames: int = 8, style: BodyStyle = BodyStyle(),
                camera: BodyCamera = BodyCamera(), progress: bool = True) -> Path:
    """Render motions as the project's skinned body to an MP4, a GIF or a PNG filmstrip.

    Args:
        motions: one or a list of (T, 22, 3) HumanML3D joints (Y-up metres) at ``fps``; side by side in an
            animation, one row each in a filmstrip.
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
            idx = np.round(np.linspace(0, len(clip) - 1, n_frames)).astype(int)
            for k, t in enumerate(idx):
                verts, normals = clip.posed(t, t + 1)
                text = clip.caption if k == 0 else ""
                cells.append(renderer.render(verts[0], normals[0], clip.lookat[t], text, f"{t / fps:.2f} s"))
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
