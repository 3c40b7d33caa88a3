"""``simdiff serve`` end to end in headless Chromium (Playwright): the page loads, generates,
regenerates from the prompt and the gravity slider, plays/scrubs and opens an uploaded file.

Skips when Playwright or a Chromium is missing. Chromium: ``$SIMDIFF_CHROMIUM``, else a system
``chromium`` (Debian: ``apt-get install chromium``), else Playwright's own download.
Screenshots go to ``$SIMDIFF_SCREENSHOT_DIR`` when set, else to tmp.
"""

from __future__ import annotations

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
def browser():
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install playwright)")
    with sync_api.sync_playwright() as playwright:
        exe = chromium_path()
        try:
            chromium = playwright.chromium.launch(executable_path=exe, args=["--no-sandbox"])
        except Exception as exc:  # no browser binary, or it cannot start here
            pytest.skip(f"no usable Chromium ({exe or 'playwright default'}): {str(exc).splitlines()[0]}")
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


def skeleton_pixels(page) -> int:
    """Canvas pixels in the left-limb blue: the skeleton was drawn."""
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
    assert skeleton_pixels(page) > 50

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
    assert "seconds must be in [0.05, 9.8], got 12" in page.text_content("#error")
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
    assert skeleton_pixels(page) > 50
    page.screenshot(path=str(screenshot_dir(tmp_path) / "viewer.png"))
    assert problems == []
