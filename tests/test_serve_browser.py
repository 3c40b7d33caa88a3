"""``simdiff serve`` end to end in headless Chromium (Playwright): the page loads, generates,
regenerates from the prompt and the gravity slider, plays/scrubs and opens an uploaded file; the WebGL view
shows the skinned body, with the stick figure as a toggle; without WebGL the page falls back to the 2D stick figure.
An open file is re-played under the sliders, a timeline of prompts is built and generated, and a pinned start pose
holds the next generation's first frame.

Skips when Playwright or a Chromium is missing. Chromium: ``$SIMDIFF_CHROMIUM``, else a system
``chromium`` (Debian: ``apt-get install chromium``), else Playwright's own download.
Screenshots go to ``$SIMDIFF_SCREENSHOT_DIR`` when set, else to tmp.
"""

from __future__ import annotations

import io
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.motion import synthetic
from simdiff.serve import MotionService, ViewerServer
from simdiff.serve.testing import write_tiny_model
from simdiff.train.testing import HashTextEncoder

pytestmark = pytest.mark.browser

REPO_ROOT = Path(__file__).resolve().parents[1]
TIMEOUT_MS = 120_000  # generous: CI machines and this one may be busy
STATE = "window.simdiffState"


def chromium_path() -> str | None:
    """A Chromium/Chrome executable, or None to let Playwright use its own."""
    env = os.environ.get("SIMDIFF_CHROMIUM")
    if env:
        return env
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        found = shutil.which(name)
        if found:
            return found
    return None


@pytest.fixture(scope="module")
def playwright():
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install playwright)")
    with sync_api.sync_playwright() as playwright:
        yield playwright


def launch(playwright, *args: str):
    exe = chromium_path()
    try:
        # software WebGL (SwiftShader) where there is no GPU: newer Chromium builds ask for it by name
        return playwright.chromium.launch(executable_path=exe, args=["--no-sandbox", "--enable-unsafe-swiftshader", *args])
    except Exception as exc:  # no browser binary, or it cannot start here
        pytest.skip(f"no usable Chromium ({exe or 'playwright default'}): {str(exc).splitlines()[0]}")


@pytest.fixture(scope="module")
def browser(playwright):
    chromium = launch(playwright)
    yield chromium
    chromium.close()


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    model = write_tiny_model(tmp_path_factory.mktemp("tiny_model"))
    srv = ViewerServer(MotionService(model, text_encoder=HashTextEncoder(), steps=4), "127.0.0.1", 0)
    srv.start_in_thread()
    yield srv
    srv.shutdown()
    srv.server_close()
    torch.set_num_threads(threads)


def screenshot_dir(tmp_path: Path) -> Path:
    folder = Path(os.environ.get("SIMDIFF_SCREENSHOT_DIR") or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def sample_motion(tmp_path: Path) -> Path:
    """A real HumanML3D clip when ../shared/data is present, else a synthetic turning walk."""
    env = os.environ.get("SIMDIFF_SHARED_DATA")
    shared = Path(env) if env else REPO_ROOT.parent / "shared" / "data"
    clip = shared / "humanml3d" / "samples" / "new_joints" / "012314.npy"
    if clip.is_file():
        return clip
    path = tmp_path / "walk.npy"
    np.save(path, synthetic.walk(80, turn_rate=0.4))
    return path


def wait_for_new_motion(page, after_id: int) -> dict:
    page.wait_for_function(f"id => {STATE}.generation_id > id && {STATE}.status === 'ready'", arg=after_id,
                           timeout=TIMEOUT_MS)
    return page.evaluate(STATE)


def wait_for_shown(page, after: int) -> dict:
    """The page state once a motion after the ``after``-th shown (any kind) is on screen."""
    page.wait_for_function(f"n => {STATE}.shown > n && {STATE}.status === 'ready'", arg=after, timeout=TIMEOUT_MS)
    return page.evaluate(STATE)


def wait_for_body(page) -> dict:
    """The viewer's numbers once the body of the motion on screen is shown."""
    page.wait_for_function(f"{STATE}.body === 'ready'", timeout=TIMEOUT_MS)
    return page.evaluate("window.simdiffViewer.debug()")


def view_pixels(page, path: Path) -> dict[str, int]:
    """Save a screenshot of the page to ``path``; count the 3D view's pixels in the stick figure's left-limb blue
    and in the body's skin tones."""
    from PIL import Image

    page.evaluate("window.simdiffPlayer._dirty = true")
    page.wait_for_timeout(300)  # a frame or two
    page.screenshot(path=str(path))
    shot = np.asarray(Image.open(io.BytesIO(page.locator("#view").screenshot())).convert("RGB")).astype(int)
    r, g, b = shot[..., 0], shot[..., 1], shot[..., 2]
    blue = (abs(r - 0x2F) < 30) & (abs(g - 0x6F) < 30) & (abs(b - 0xD0) < 30)
    skin = (r > g + 10) & (g > b + 5) & (b > 70) & (r - b > 25)
    return {"blue": int(blue.sum()), "skin": int(skin.sum())}


def skeleton_pixels(page) -> int:
    """2D view (no WebGL): canvas pixels in the left-limb blue, the skeleton was drawn."""
    return page.evaluate("""() => {
        const c = document.getElementById('view');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) {
            if (Math.abs(d[i] - 0x2f) < 30 && Math.abs(d[i + 1] - 0x6f) < 30 && Math.abs(d[i + 2] - 0xd0) < 30) n++;
        }
        return n;
    }""")


def test_viewer_generates_regenerates_plays_and_opens(browser, server, tmp_path):
    page = browser.new_page(viewport={"width": 1280, "height": 760})
    problems: list[str] = []
    page.on("pageerror", lambda exc: problems.append(f"page error: {exc}"))
    page.on("console", lambda msg: problems.append(f"console: {msg.text}")
            if msg.type == "error" and "status of 400" not in msg.text else None)  # the 400 below is on purpose
    page.goto(server.url)

    # the first motion is generated with the defaults as soon as the page loads
    first = wait_for_new_motion(page, 0)
    assert first["generation_id"] == 1 and first["frames"] == 120 and first["source"] == "generate"
    assert first["params"]["gravity"] == pytest.approx(-9.81) and first["error"] is None
    assert first["view"] == "webgl" and wait_for_body(page)["skinnedMeshes"] == 1

    # type a prompt, press Generate
    page.fill("#prompt", "a person jumps on the spot")
    page.fill("#seconds", "3")
    page.click("#generate")
    second = wait_for_new_motion(page, first["generation_id"])
    assert second["params"]["text"] == "a person jumps on the spot" and second["frames"] == 60
    assert second["digest"] != first["digest"]

    # move the gravity slider: releasing it regenerates with the new φ
    page.fill("#gravity", "-3")
    third = wait_for_new_motion(page, second["generation_id"])
    assert third["params"]["gravity"] == pytest.approx(-3.0) and third["params"]["text"] == "a person jumps on the spot"
    assert third["frames"] == 60 and third["digest"] != second["digest"]
    assert page.text_content("#gravity-value") == "-3"  # the exact value, up to 3 decimals
    page.screenshot(path=str(screenshot_dir(tmp_path) / "viewer_generate.png"))

    # the foot-lock box starts at the model's sampling.json (none here: off) and is sent with the request
    assert third["params"]["foot_lock"] == 0 and not page.is_checked("#foot_lock")
    page.check("#foot_lock")
    page.click("#generate")
    locked = wait_for_new_motion(page, third["generation_id"])
    assert locked["params"]["foot_lock"] == 1 and locked["meta"]["sampling"]["foot_lock"] == 1
    page.uncheck("#foot_lock")
    page.click("#generate")
    third = wait_for_new_motion(page, locked["generation_id"])
    assert third["params"]["foot_lock"] == 0

    # the environment-guidance slider starts at the model's value (none here: 1, off); moving it regenerates
    assert third["params"]["env_guidance"] == 1 and page.input_value("#env_guidance") == "1"
    page.fill("#env_guidance", "3")
    pushed = wait_for_new_motion(page, third["generation_id"])
    assert pushed["params"]["env_guidance"] == 3 and pushed["meta"]["sampling"]["env_guidance"] == 3
    assert pushed["digest"] != third["digest"]  # g = −3: off Earth, so the motion changes
    page.fill("#env_guidance", "1")
    third = wait_for_new_motion(page, pushed["generation_id"])
    assert third["params"]["env_guidance"] == 1

    # timeline: pause, scrub
    assert page.evaluate(f"{STATE}.playing") is True
    page.click("#play")
    assert page.evaluate(f"{STATE}.playing") is False
    page.fill("#scrub", "25")
    assert page.evaluate(f"{STATE}.frame") == 25
    assert page.text_content("#time") == "1.25 / 2.95 s"

    # a bad request shows the server's one-line message, and the motion stays
    page.fill("#seconds", "12")
    page.click("#generate")
    page.wait_for_function(f"{STATE}.status === 'error'", timeout=TIMEOUT_MS)
    assert "seconds must be in [0.5, 9.8], got 12" in page.text_content("#error")
    assert page.evaluate(f"{STATE}.frames") == 60
    page.fill("#seconds", "6")

    # open a motion file through the upload control
    motion = sample_motion(tmp_path)
    page.set_input_files("#file-input", str(motion))
    page.wait_for_function(f"{STATE}.source === 'upload' && {STATE}.status === 'ready'", timeout=TIMEOUT_MS)
    opened = page.evaluate(STATE)
    assert opened["frames"] == np.load(motion).shape[0] and opened["meta"]["name"] == motion.name
    assert page.is_hidden("#error")
    page.click("#play")
    page.fill("#scrub", str(opened["frames"] * 2 // 3))
    page.mouse.move(900, 400)
    page.mouse.down()
    page.mouse.move(960, 380, steps=4)  # orbit a little
    page.mouse.up()
    viewer = wait_for_body(page)  # an opened motion has its body too
    assert viewer["skinnedMeshes"] == 1 and viewer["bones"] == 22 and viewer["boneErrorMm"] < 50
    assert view_pixels(page, screenshot_dir(tmp_path) / "viewer.png")["skin"] > 1000
    assert problems == []


def test_body_with_stick_figure_toggle_and_no_outside_requests(browser, server, tmp_path):
    page = browser.new_page(viewport={"width": 1280, "height": 760})
    problems: list[str] = []
    requests: list[str] = []
    page.on("pageerror", lambda exc: problems.append(f"page error: {exc}"))
    page.on("console", lambda msg: problems.append(f"console: {msg.text}") if msg.type == "error" else None)
    page.on("request", lambda request: requests.append(request.url))
    page.goto(server.url)
    first = wait_for_new_motion(page, 0)
    viewer = wait_for_body(page)
    assert viewer == {**viewer, "renderer": "webgl", "skinnedMeshes": 1, "bones": 22, "body": "ready", "stick": False}
    assert viewer["boneErrorMm"] < 1.0  # the body's bones sit on the joints the stick figure draws

    page.click("#play")  # pause, then look at the first, a middle and the last frame
    for frame in (0, first["frames"] // 2, first["frames"] - 1):
        page.fill("#scrub", str(frame))
        viewer = page.evaluate("window.simdiffViewer.debug()")
        assert viewer["frame"] == frame and viewer["boneErrorMm"] < 1.0, viewer
    folder = screenshot_dir(tmp_path)
    body_only = view_pixels(page, folder / "viewer_body.png")
    assert body_only["skin"] > 1000 and body_only["blue"] < 20, body_only

    page.check("#stick")
    assert page.evaluate(f"{STATE}.stick") is True and page.evaluate("window.simdiffViewer.debug().stick") is True
    with_stick = view_pixels(page, folder / "viewer_body_stick.png")
    assert with_stick["blue"] > 50 and with_stick["skin"] > 500, with_stick
    page.uncheck("#stick")
    assert page.evaluate("window.simdiffViewer.debug().stick") is False

    # a new motion replaces the body (one skinned mesh in the scene, never two)
    page.fill("#seconds", "2")
    page.click("#generate")
    second = wait_for_new_motion(page, first["generation_id"])
    viewer = wait_for_body(page)
    assert second["frames"] == 40 and viewer["skinnedMeshes"] == 1 and viewer["boneErrorMm"] < 1.0

    assert requests and all(url.startswith(server.url) for url in requests), requests
    assert any("/static/vendor/three/" in url for url in requests) and any(url.endswith(".glb") for url in requests)
    assert problems == []


def test_without_webgl_the_page_draws_the_stick_figure(playwright, server, tmp_path):
    chromium = launch(playwright, "--disable-3d-apis", "--disable-webgl")
    try:
        page = chromium.new_page(viewport={"width": 1000, "height": 700})
        errors: list[str] = []
        page.on("pageerror", lambda exc: errors.append(f"page error: {exc}"))
        page.goto(server.url)
        state = wait_for_new_motion(page, 0)
        assert state["view"] == "2d" and state["body"] is None and page.is_hidden("#stick")
        assert skeleton_pixels(page) > 50
        assert "No WebGL" in page.text_content("#model-info")
        page.screenshot(path=str(screenshot_dir(tmp_path) / "viewer_2d.png"))
        assert errors == []
    finally:
        chromium.close()


def test_viewer_replays_a_file_builds_a_timeline_and_pins_a_pose(browser, server, tmp_path):
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    problems: list[str] = []
    page.on("pageerror", lambda exc: problems.append(f"page error: {exc}"))
    page.on("console", lambda msg: problems.append(f"console: {msg.text}")
            if msg.type == "error" and "status of 400" not in msg.text else None)  # the bad row below is on purpose
    page.goto(server.url)
    wait_for_new_motion(page, 0)
    assert page.is_hidden("#replay")  # nothing to re-play before a file is open
    folder = screenshot_dir(tmp_path)

    # open a file: the re-play button shows; the sliders re-play it instead of generating
    motion = sample_motion(tmp_path)
    page.set_input_files("#file-input", str(motion))
    page.wait_for_function(f"{STATE}.source === 'upload' && {STATE}.status === 'ready'", timeout=TIMEOUT_MS)
    opened = page.evaluate(STATE)
    assert opened["file_motion"] == opened["motion"] and page.is_visible("#replay")
    page.fill("#gravity", "-3")
    slid = wait_for_shown(page, opened["shown"])
    assert slid["source"] == "edit" and slid["params"]["source"] == opened["motion"]
    assert slid["params"]["gravity"] == pytest.approx(-3.0) and slid["frames"] == opened["frames"]
    assert slid["digest"] != opened["digest"] and slid["generation_id"] == opened["generation_id"]

    # the button re-plays the open file (not the re-play on screen) under the sliders as they are
    page.evaluate("(s => { s.value = '6'; s.dispatchEvent(new Event('input')); })(document.getElementById('wind_y'))")
    page.click("#replay")
    replayed = wait_for_shown(page, slid["shown"])
    assert replayed["source"] == "edit" and replayed["params"]["source"] == opened["motion"]
    assert replayed["params"]["wind_y"] == pytest.approx(6.0) and replayed["file_motion"] == opened["motion"]
    assert replayed["meta"]["changed_m"] > 0 and set(replayed["meta"]["gravity_read"]) == {"input", "edited"}
    assert motion.name in page.text_content("#caption") and "Re-played" in page.text_content("#status")
    wait_for_body(page)
    page.screenshot(path=str(folder / "viewer_replay.png"))

    # a two-row timeline: the builder starts with the prompt box's row; add one, fill both, generate
    page.click("#timeline-builder summary")
    page.click("#add-segment")
    rows = page.locator("#segments .segment")
    assert rows.count() == 2
    rows.nth(0).locator(".seg-text").fill("a person walks forward")
    rows.nth(0).locator(".seg-seconds").fill("1.5")
    rows.nth(1).locator(".seg-text").fill("a person jumps")
    rows.nth(1).locator(".seg-seconds").fill("1")
    rows.nth(1).locator(".seg-gravity").fill("-1.6")
    rows.nth(1).locator(".seg-wind-x").fill("2")
    page.click("#generate-timeline")
    line = wait_for_shown(page, replayed["shown"])
    assert line["source"] == "timeline" and line["frames"] == 50 and line["file_motion"] is None
    assert [(s["text"], s["frames"], s["gravity"], s["wind"]) for s in line["meta"]["segments"]] == [
        ("a person walks forward", [0, 30], -9.81, [0.0, 0.0]), ("a person jumps", [30, 50], -1.6, [2.0, 0.0])]
    assert page.is_hidden("#replay") and "→" in page.text_content("#caption")
    wait_for_body(page)
    page.screenshot(path=str(folder / "viewer_timeline.png"))

    # a bad row shows the server's one-line message, the motion stays
    rows.nth(1).locator(".seg-seconds").fill("30")
    page.click("#generate-timeline")
    page.wait_for_function(f"{STATE}.status === 'error'", timeout=TIMEOUT_MS)
    assert "the timeline: segment 1: seconds 30 is outside" in page.text_content("#error")
    assert page.evaluate(f"{STATE}.motion") == line["motion"]
    rows.nth(1).locator(".seg-remove").click()
    assert rows.count() == 1

    # pin the start pose of the timeline on screen, then generate: the next motion starts in that pose
    first_pose = page.evaluate("window.simdiffPlayer.motion.joints[0]")
    page.check("#pin_start")
    assert page.evaluate(f"{STATE}.pins") == {"start": line["motion"], "end": None} and page.is_visible("#pin-note")
    page.fill("#seconds", "2")
    page.click("#generate")
    pinned = wait_for_new_motion(page, line["generation_id"])
    assert pinned["frames"] == 40 and pinned["meta"]["pins"] == {"start": line["motion"], "end": None}
    assert pinned["params"]["pin_start"] == line["motion"] and pinned["meta"]["keyframe_error_cm"] < 2.0
    start = np.asarray(page.evaluate("window.simdiffPlayer.motion.joints[0]"))
    assert np.linalg.norm(start - np.asarray(first_pose), axis=-1).max() < 0.02
    assert "Pinned start pose met within" in page.text_content("#status")
    wait_for_body(page)
    page.click("#play")
    page.fill("#scrub", "0")
    page.screenshot(path=str(folder / "viewer_pins.png"))
    page.uncheck("#pin_start")
    assert page.evaluate(f"{STATE}.pins") == {"start": None, "end": None} and page.is_hidden("#pin-note")
    assert problems == [], problems
