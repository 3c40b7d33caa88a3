"""Every ``simdiff`` command that README.md and docs/tutorial.md show runs, in a short form, in document order.

Short form: ``generate`` and ``sample`` draw 0.5 s motions with 2 denoising steps; ``serve`` starts on a free port
and answers one page request. Each document's commands run in order in one empty folder, so a command may use the
files an earlier one wrote (as a reader following the document would).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from simdiff.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
DOCS = ("README.md", "docs/tutorial.md")
SHORT = {"--length": "0.5", "--steps": "2"}


def commands(doc: str) -> list[str]:
    """The literal ``simdiff ...`` commands of ``doc``: lines of its bash blocks (the last part of a ``&&`` chain)
    and inline ``simdiff generate TEXT ...`` spans without placeholders."""
    text = (ROOT / doc).read_text(encoding="utf-8")
    found: list[str] = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            part = line.split("&&")[-1].strip()
            if part.startswith("simdiff "):
                found.append(part)
    for span in re.findall(r"`(simdiff generate [^`]+)`", text):  # a whole command shown inline, e.g. a figure's
        if not re.search(r"[A-Z]{2,}|\[|\||\.\.\.|…", span) and span not in found:
            found.append(span)
    return found


def shorten(argv: list[str]) -> list[str]:
    """``generate``/``sample`` argv with a short length and few steps."""
    if argv[0] not in ("generate", "sample"):
        return argv
    out = list(argv)
    for flag, value in SHORT.items():
        if flag in out:
            out[out.index(flag) + 1] = value
        else:
            out += [flag, value]
    return out


def serve_once(argv: list[str], cwd: Path) -> None:
    """Start ``simdiff serve`` on a free port, fetch its page once, stop it."""
    proc = subprocess.Popen([sys.executable, "-m", "simdiff", *argv, "--port", "0", "--no-browser"], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        deadline = time.monotonic() + 60
        url = None
        assert proc.stdout is not None
        while url is None and time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            match = re.search(r"http://127\.0\.0\.1:\d+/", line)
            url = match.group(0) if match else None
        assert url, "simdiff serve printed no address"
        with urllib.request.urlopen(url, timeout=30) as page:
            assert page.status == 200
    finally:
        proc.terminate()
        proc.wait(timeout=30)


@pytest.mark.parametrize("doc", DOCS)
def test_every_documented_command_runs(doc: str, tmp_path: Path, monkeypatch) -> None:
    found = commands(doc)
    assert found, f"{doc} shows no simdiff command"
    monkeypatch.chdir(tmp_path)
    for command in found:
        argv = shorten(shlex.split(command)[1:])
        if argv[0] == "serve":
            serve_once(argv, tmp_path)
            continue
        assert main(argv) == 0, f"{doc}: `{command}` failed"


def test_tutorial_python_gives_the_joints_generate_writes(tmp_path: Path, monkeypatch) -> None:
    """The tutorial's Python example runs and, with the same prompt, φ and seed, gives ``simdiff generate``'s joints."""
    import numpy as np

    code = re.findall(r"```python\n(.*?)```", (ROOT / "docs/tutorial.md").read_text(encoding="utf-8"), flags=re.S)[-1]
    code = code.replace("120, config", "20, config.updated(steps=2)")
    scope: dict = {}
    exec(compile(code, "tutorial.md", "exec"), scope)  # noqa: S102 - the documented example itself
    monkeypatch.chdir(tmp_path)
    assert main(["generate", "a person jumps forward", "--gravity", "-3.7", "--wind", "2", "0", "--length", "1",
                 "--steps", "2", "--format", "npy", "--out", "o", "-q"]) == 0
    written = np.load(tmp_path / "o" / "sample0_joints.npy")
    assert scope["joints"].shape == written.shape == (20, 22, 3)
    assert float(np.abs(scope["joints"] - written).max()) < 1e-5


def test_commands_are_found() -> None:
    readme = commands("README.md")
    assert any(c.startswith("simdiff generate") for c in readme)
    assert shorten(["generate", "x", "--length", "8"]) == ["generate", "x", "--length", "0.5", "--steps", "2"]
    assert os.path.isfile(ROOT / "docs" / "tutorial.md")
