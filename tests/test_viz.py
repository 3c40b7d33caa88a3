"""Stick-figure rendering: files written with the right frame counts and sizes; panels share one scale; bad input rejected."""

from __future__ import annotations

from pathlib import Path

import imageio.v2 as iio2
import imageio.v3 as iio
import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.synthetic import jump, walk
from simdiff.viz import animation_frames, render_animation, render_filmstrip
from simdiff.viz.camera import choose_azim, clip_bounds, content_points, screen_points, to_plot, view_basis
from simdiff.viz.panel import StickPanel
from simdiff.viz.stick import AnimationScene, filmstrip_figure

SMALL = dict(panel_size=(1.6, 1.6), dpi=50)  # 80 x 80 px panels


@pytest.fixture(scope="module")
def walks() -> list[np.ndarray]:
    return [walk(12), walk(7, speed=0.5)]


def test_synthetic_walk_is_upright_on_floor() -> None:
    j = walk(40)
    assert j.shape == (40, 22, 3) and j.dtype == np.float32
    assert abs(j[..., 1].min()) < 1e-6 and j[:, [7, 8, 10, 11], 1].min(axis=1).max() < 0.05
    assert (j[:, 15, 1] > 1.3).all()  # head well above the floor
    assert j[-1, 0, 2] > j[0, 0, 2]  # walks towards +Z


def test_gif_frames_and_size(tmp_path: Path, walks: list[np.ndarray]) -> None:
    out = render_animation(walks, tmp_path / "a.gif", captions=["walk", "slow walk"], **SMALL)
    frames = iio.imread(out, index=None)
    assert frames.shape[0] == 12  # the longest clip; the shorter one holds its last frame
    assert frames.shape[2] == 160 and frames.shape[1] > 80  # two 80-px panels side by side, captions on top
    assert iio.immeta(out, index=0)["duration"] == 50  # 20 fps


def test_mp4_frames_and_size(tmp_path: Path, walks: list[np.ndarray]) -> None:
    out = render_animation(walks[1], tmp_path / "a.mp4", **SMALL)
    with iio2.get_reader(out, format="FFMPEG") as reader:
        meta = reader.get_meta_data()
        n = reader.count_frames()
    assert n == 7
    assert meta["size"] == (80, 80)
    assert meta["fps"] == pytest.approx(20)


def test_animation_frames_match_video(walks: list[np.ndarray]) -> None:
    frames = list(animation_frames(walks, **SMALL))  # no captions: no caption band
    assert len(frames) == 12 and frames[0].shape == (80, 160, 3) and frames[0].dtype == np.uint8
    assert not np.array_equal(frames[0], frames[-1])  # the figures move
    assert (frames[0] < 250).any()  # something is drawn


def test_filmstrip_png(tmp_path: Path, walks: list[np.ndarray]) -> None:
    out = render_filmstrip(walks, tmp_path / "sub" / "f.png", n_frames=3, cell_size=(1.0, 1.0), dpi=50)
    assert iio.imread(out).shape[:2] == (2 * 50, 3 * 50)  # 2 rows (motions) x 3 columns (frames)
    out = render_filmstrip(walks, tmp_path / "g.png", captions=["a", "b"], n_frames=3, cell_size=(1.0, 1.0), dpi=50)
    image = iio.imread(out)
    assert image.shape[1] == 150 and image.shape[0] > 100  # captions add a band above each row


def test_fixed_camera_covers_whole_clip() -> None:
    j = walk(60)
    lo, hi = clip_bounds(j)
    pts = to_plot(j.reshape(-1, 3))
    assert (pts >= lo - 1e-6).all() and (pts <= hi + 1e-6).all() and lo[2] <= 0.0
    assert -180.0 <= choose_azim(j) <= 180.0


@pytest.mark.parametrize(
    "motions",
    [[], [np.zeros((5, 21, 3))], [np.zeros((5, 22))], [np.zeros((0, 22, 3))], [np.full((3, 22, 3), np.nan)], "x"],
)
def test_bad_motions(tmp_path: Path, motions: object) -> None:
    with pytest.raises(SimdiffError):
        render_animation(motions, tmp_path / "a.gif", **SMALL)  # type: ignore[arg-type]
    with pytest.raises(SimdiffError):
        render_filmstrip(motions, tmp_path / "a.png")  # type: ignore[arg-type]


def test_bad_options(tmp_path: Path, walks: list[np.ndarray]) -> None:
    with pytest.raises(SimdiffError, match="avi"):
        render_animation(walks, tmp_path / "a.avi")
    with pytest.raises(SimdiffError, match="gif"):
        render_filmstrip(walks, tmp_path / "a.gif")
    with pytest.raises(SimdiffError, match="captions"):
        render_animation(walks, tmp_path / "a.gif", captions=["only one"])
    with pytest.raises(SimdiffError, match="n_frames"):
        render_filmstrip(walks, tmp_path / "a.png", n_frames=0)
    with pytest.raises(SimdiffError, match="fps"):
        render_animation(walks, tmp_path / "a.gif", fps=-1)


def test_cli_render(tmp_path: Path, walks: list[np.ndarray]) -> None:
    from simdiff.cli.main import main

    files = []
    for i, w in enumerate(walks):
        files.append(str(tmp_path / f"m{i}.npy"))
        np.save(files[-1], w)
    out = tmp_path / "f.png"
    assert main(["render", *files, "--out", str(out), "--frames", "2", "--caption", "a", "b"]) == 0
    assert out.is_file()
    assert main(["render", files[0], "--out", str(tmp_path / "a.webm")]) == 2
    assert main(["render", str(tmp_path / "missing.npy"), "--out", str(out)]) == 2
    np.save(tmp_path / "bad.npy", np.zeros((4, 3)))
    assert main(["render", str(tmp_path / "bad.npy"), "--out", str(out)]) == 2


SHIN = (4, 7)  # left knee, left ankle: a bone of constant length in both synthetic motions


def _px_per_metre(panel: StickPanel, motion: np.ndarray) -> np.ndarray:
    """(T,) screen length of the shin in display pixels over its length in the view plane in metres."""
    bone = motion[:, list(SHIN)].astype(np.float64)
    px = np.linalg.norm(np.diff(panel.screen(bone), axis=1)[:, 0], axis=-1)
    right, up = view_basis(panel.ax.elev, panel.ax.azim)
    d = to_plot(bone[:, 1] - bone[:, 0])
    return px / np.hypot(d @ right, d @ up)


def _inside(panel: StickPanel, motion: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Display-pixel box (lo, hi) of the panel's rectangle and the screen points of every joint of every frame."""
    box = panel.rect.transformed(panel.ax.get_figure().transFigure)
    return np.array([box.x0, box.y0]), np.array([box.x1, box.y1]), panel.screen(motion.reshape(-1, 3))


def _fills(panel: StickPanel, motion: np.ndarray) -> bool:
    """Whether the panel's content (joints and floor) spans its rectangle, less the 6 px (at 100 dpi) pad, on one side."""
    fig = panel.ax.get_figure()
    box = panel.rect.transformed(fig.transFigure)
    free = np.array([box.width, box.height]) - 2 * 6.0 * fig.dpi / 100
    xy = screen_points(panel.ax, content_points(motion, *clip_bounds(motion)))
    return bool((np.abs(np.ptp(xy, axis=0) - free) < 0.5).any())


@pytest.fixture(scope="module")
def jump_and_walk() -> list[np.ndarray]:
    return [jump(40, height=0.5), walk(80)]  # in place / 5 m of travel


def _check_shared_scale(panels: list[StickPanel], motions: list[np.ndarray]) -> None:
    assert max(p.fill_scale for p in panels) > 1.3 * min(p.fill_scale for p in panels)  # fitted alone, they differ
    assert len({(p.ax.elev, p.ax.azim) for p in panels}) == 1
    scales = np.concatenate([_px_per_metre(p, m) for p, m in zip(panels, motions)])
    assert np.ptp(scales) < 0.02 * scales.mean()  # one metres-per-pixel across panels
    for p, m in zip(panels, motions):
        lo, hi, xy = _inside(p, m)
        assert (xy >= lo - 0.5).all() and (xy <= hi + 0.5).all()  # every joint of every frame in its panel


def test_filmstrip_rows_share_one_scale(jump_and_walk: list[np.ndarray]) -> None:
    fig, rows = filmstrip_figure(jump_and_walk, ["jump", "walk"], n_frames=3, cell_size=(1.6, None), dpi=60)
    fig.canvas.draw()
    panels = [p for row in rows for p in row]
    motions = [m for row, m in zip(rows, jump_and_walk) for _ in row]
    _check_shared_scale(panels, motions)


def test_animation_panels_share_one_scale(jump_and_walk: list[np.ndarray]) -> None:
    scene = AnimationScene(jump_and_walk, ["jump", "walk"], panel_size=(2.0, None), dpi=60)
    scene.frame(0)
    _check_shared_scale(scene.panels, jump_and_walk)
    walk_panel = scene.panels[1]  # the largest content sets the scale and fills its panel
    assert walk_panel.scale == pytest.approx(walk_panel.fill_scale) and _fills(walk_panel, jump_and_walk[1])
    assert not _fills(scene.panels[0], jump_and_walk[0])


@pytest.mark.parametrize("which", [0, 1])
def test_single_motion_fills_its_panel(jump_and_walk: list[np.ndarray], which: int) -> None:
    motion = jump_and_walk[which]
    scene = AnimationScene([motion], [""], panel_size=(2.0, None), dpi=60)
    scene.frame(0)
    fig, rows = filmstrip_figure([motion], [""], n_frames=2, cell_size=(1.6, None), dpi=60)
    fig.canvas.draw()
    for panel in [*scene.panels, *rows[0]]:
        assert panel.scale == pytest.approx(panel.fill_scale)
        lo, hi, xy = _inside(panel, motion)
        assert (xy >= lo - 0.5).all() and (xy <= hi + 0.5).all()
        assert _fills(panel, motion)



def test_a_long_walk_keeps_a_readable_body_in_the_filmstrip() -> None:
    """Past LOCAL_VIEW_M of travel each cell draws its own stretch: the body stays tens of pixels tall."""
    from simdiff.viz.stick import LOCAL_VIEW_M

    long_walk = walk(400, speed=1.5)  # 30 m
    short_walk = walk(80, speed=1.5)  # 6 m: drawn whole
    assert np.ptp(long_walk[:, 0, 2]) > 3 * LOCAL_VIEW_M
    fig, rows = filmstrip_figure([long_walk], [""], n_frames=8, dpi=100)
    fig.canvas.draw()
    body_px = [float(np.ptp(p.screen(long_walk[0])[:, 1])) for p in rows[0]]
    assert min(body_px) > 30  # the whole 30 m drawn in each cell leaves 8
    _, short_rows = filmstrip_figure([short_walk], [""], n_frames=4, dpi=100)
    assert all(p.n_frames == 80 for p in short_rows[0])
