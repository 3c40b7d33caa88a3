"""Failure cases of outputs, the server and the CLI: one-line errors, nothing half-written.

Read-only outputs and full disks are simulated (tests may run as root, where ``chmod`` does not
block writes): ``os.replace`` raising ``EROFS``, a writer that writes half the bytes and then
raises ``ENOSPC``, a folder path that is a file. The server runs in a thread on port 0 with a
stub service (no model) and short timeouts.
"""

from __future__ import annotations

import errno
import http.client
import json
import os
import socket
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from simdiff import fsio
from simdiff.cli.main import main
from simdiff.motion import synthetic
from simdiff.product.request import MAX_PROMPT_CHARS
from simdiff.serve import MotionService, ViewerServer
from simdiff.serve.params import MAX_STEPS


@pytest.fixture(scope="module")
def joints_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("motion") / "squat.npy"
    np.save(path, synthetic.walk(16).astype(np.float32))
    return path


def _one_line_error(capsys, *needles: str) -> str:
    err = capsys.readouterr().err.strip()
    lines = [line for line in err.splitlines() if line.startswith("simdiff: error:")]
    assert len(lines) == 1, err
    assert "Traceback" not in err, err
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if p.is_file())


def _read_only_replace(monkeypatch) -> None:
    def refuse(src, dst, *args, **kwargs):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(dst))

    monkeypatch.setattr(fsio.os, "replace", refuse)


class _HalfThenFull:
    """A file object that writes half of the first chunk it gets, then raises ENOSPC."""

    def __init__(self, handle) -> None:
        self.handle = handle

    def write(self, data) -> int:
        data = bytes(data)
        self.handle.write(data[: max(1, len(data) // 2)])
        self.handle.flush()
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def __getattr__(self, name: str) -> Any:
        return getattr(self.handle, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.handle.close()


def _full_disk(monkeypatch) -> None:
    real_open = open

    def fake_open(path, mode="r", *args, **kwargs):
        handle = real_open(path, mode, *args, **kwargs)
        return _HalfThenFull(handle) if "w" in mode else handle

    monkeypatch.setattr(fsio, "open", fake_open, raising=False)


# -- file outputs --------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["out.bvh", "out.npy"])
def test_convert_read_only(joints_file, tmp_path, monkeypatch, capsys, name):
    _read_only_replace(monkeypatch)
    assert main(["convert", str(joints_file), str(tmp_path / name)]) == 2
    _one_line_error(capsys, str(tmp_path / name), "read-only file system")
    assert _files(tmp_path) == []


@pytest.mark.parametrize("name", ["out.bvh", "out.npy"])
def test_convert_full_disk_leaves_nothing(joints_file, tmp_path, monkeypatch, capsys, name):
    _full_disk(monkeypatch)
    assert main(["convert", str(joints_file), str(tmp_path / name)]) == 2
    _one_line_error(capsys, str(tmp_path / name), "no space left on device")
    assert _files(tmp_path) == []


def test_convert_full_disk_keeps_the_old_file(joints_file, tmp_path, monkeypatch, capsys):
    target = tmp_path / "out.bvh"
    assert main(["convert", str(joints_file), str(target)]) == 0
    before = target.read_bytes()
    _full_disk(monkeypatch)
    assert main(["convert", str(joints_file), str(target)]) == 2
    assert target.read_bytes() == before and _files(tmp_path) == ["out.bvh"]


def test_output_folder_is_a_file(joints_file, tmp_path, capsys):
    blocker = tmp_path / "blocker"
    blocker.write_text("not a folder")
    assert main(["convert", str(joints_file), str(blocker / "out.bvh")]) == 2
    _one_line_error(capsys, "blocker")
    assert main(["render", str(joints_file), "--out", str(blocker / "r.gif")]) == 2
    _one_line_error(capsys, "blocker")
    assert main(["track", str(joints_file), "--out", str(blocker / "t")]) == 2
    _one_line_error(capsys, "blocker")
    assert main(["generate", "a person walks", "--out", str(blocker / "g")]) == 2  # before loading the model
    _one_line_error(capsys, "blocker")


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root ignores folder permissions")
def test_convert_into_read_only_folder(joints_file, tmp_path, capsys):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        assert main(["convert", str(joints_file), str(folder / "c.bvh")]) == 2
        _one_line_error(capsys, "permission denied")
        assert _files(folder) == []
    finally:
        folder.chmod(0o700)


@pytest.mark.parametrize("name", ["r.gif", "r.png"])
def test_render_read_only_and_full_disk(joints_file, tmp_path, monkeypatch, capsys, name):
    with monkeypatch.context() as m:
        _read_only_replace(m)
        assert main(["render", str(joints_file), "--out", str(tmp_path / name)]) == 2
        _one_line_error(capsys, str(tmp_path / name), "read-only file system")
    assert _files(tmp_path) == []

    from PIL import Image

    def half_then_full(self, fp, *args, **kwargs):
        Path(fp).write_bytes(b"GIF89a-half")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Image.Image, "save", half_then_full)
    monkeypatch.setattr("matplotlib.figure.Figure.savefig", lambda self, fp, **kw: half_then_full(self, fp))
    assert main(["render", str(joints_file), "--out", str(tmp_path / name)]) == 2
    _one_line_error(capsys, str(tmp_path / name), "no space left on device")
    assert _files(tmp_path) == []


def test_mp4_encoder_failure_leaves_nothing(tmp_path, monkeypatch):
    from simdiff.errors import SimdiffError
    from simdiff.viz.video import write_mp4

    def frames():
        yield np.zeros((16, 16, 3), np.uint8)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    with pytest.raises(SimdiffError, match="no space left on device"):
        write_mp4(frames(), tmp_path / "v.mp4", 20)
    assert _files(tmp_path) == []


def test_audit_read_only(joints_file, tmp_path, monkeypatch, capsys):
    _read_only_replace(monkeypatch)
    out = tmp_path / "audit"
    assert main(["audit", str(joints_file), "--no-track", "--out", str(out)]) == 2
    _one_line_error(capsys, "read-only file system")
    assert _files(tmp_path) == []


def test_generate_outputs_full_disk(tmp_path, monkeypatch):
    from simdiff.errors import SimdiffError
    from simdiff.motion.features import joints_to_features
    from simdiff.product.outputs import write_metadata, write_motion

    joints = synthetic.walk(12)
    features = joints_to_features(joints)
    _full_disk(monkeypatch)
    for call in (lambda: write_motion(tmp_path / "sample0", joints, features, ("npy", "bvh")),
                 lambda: write_motion(tmp_path / "sample0", joints, features, ("bvh",)),
                 lambda: write_metadata(tmp_path / "generation.json", {"a": 1})):
        with pytest.raises(SimdiffError, match="no space left on device"):
            call()
        assert _files(tmp_path) == []


def test_atomic_path_passes_writer_bugs_and_cleans_up(tmp_path):
    with pytest.raises(ZeroDivisionError):
        with fsio.atomic_path(tmp_path / "x.txt") as tmp:
            tmp.write_text("partial")
            1 / 0
    assert _files(tmp_path) == []
    assert fsio.write_json(tmp_path / "ok.json", {"a": 1}).read_text() == '{\n  "a": 1\n}\n'


# -- CLI prompt limit ----------------------------------------------------------------------------


def test_cli_long_prompt_is_refused_before_loading(tmp_path, capsys):
    text = "a person walks " * 700  # about 10,000 characters
    assert main(["generate", text, "--out", str(tmp_path / "g"), "--model", str(tmp_path / "no-model")]) == 2
    _one_line_error(capsys, f"the limit is {MAX_PROMPT_CHARS}")
    assert not (tmp_path / "g").exists()


# -- server --------------------------------------------------------------------------------------


class _BlockingService(MotionService):
    """A service whose generation waits for ``release`` (no model): lets a test fill the queue."""

    def __init__(self, tmp: Path, max_queue: int) -> None:
        super().__init__(tmp / "no-model", max_queue=max_queue)
        self.release = threading.Event()
        self.started = threading.Event()

    def _generate_admitted(self, params, keys, position, queued):
        self.started.set()
        self.release.wait(10)
        return {"joints": [], "meta": {"queue_position": position}}


@pytest.fixture()
def blocking_server(tmp_path):
    service = _BlockingService(tmp_path, max_queue=0)
    server = ViewerServer(service, "127.0.0.1", 0, request_timeout=0.5, max_connections=4)
    server.start_in_thread()
    yield server
    service.release.set()
    server.shutdown()
    server.server_close()


def _request(server: ViewerServer, method: str, path: str, body: bytes | None = None,
             content_type: str = "application/json") -> tuple[int, dict[str, str], bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", server.port, timeout=10)
    headers = {"Content-Type": content_type} if body is not None else {}
    conn.request(method, path, body=body, headers=headers)
    response = conn.getresponse()
    data = response.read()
    conn.close()
    return response.status, dict(response.getheaders()), data


def test_server_head(blocking_server):
    status, headers, data = _request(blocking_server, "HEAD", "/")
    assert status == 200 and data == b"" and int(headers["Content-Length"]) > 0
    assert _request(blocking_server, "HEAD", "/api/info")[0] == 200


def test_server_nested_json_is_400(blocking_server):
    status, _, data = _request(blocking_server, "POST", "/api/generate", b"[" * 30000)
    assert status == 400 and "JSON" in json.loads(data)["error"]
    status, _, _ = _request(blocking_server, "POST", "/api/generate", b'{"text": ' + b"[" * 30000 + b"]" * 30000 + b"}")
    assert status == 400


def test_server_long_prompt_same_limit_as_cli(blocking_server):
    body = json.dumps({"text": "x" * (MAX_PROMPT_CHARS + 1)}).encode()
    status, _, data = _request(blocking_server, "POST", "/api/generate", body)
    assert status == 400 and f"the limit is {MAX_PROMPT_CHARS}" in json.loads(data)["error"]


def test_server_step_cap(blocking_server):
    body = json.dumps({"text": "walk", "steps": MAX_STEPS + 1}).encode()
    status, _, data = _request(blocking_server, "POST", "/api/generate", body)
    assert status == 400 and f"[1, {MAX_STEPS}]" in json.loads(data)["error"]


def test_server_stalled_client_is_cut_off(blocking_server):
    start = time.perf_counter()
    with socket.create_connection(("127.0.0.1", blocking_server.port), timeout=5) as sock:
        sock.sendall(b"POST /api/generate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                     b"Content-Length: 1000\r\n\r\n{\"text\": \"a\"")
        answer = b""
        while chunk := sock.recv(4096):  # the server answers and closes: recv returns b"" at the end
            answer += chunk
    assert time.perf_counter() - start < 4.0
    assert answer == b"" or answer.split(b" ")[1] in (b"408", b"400"), answer[:80]


def test_server_queue_full_gives_429_with_position(blocking_server):
    service: _BlockingService = blocking_server.service  # type: ignore[assignment]
    body = json.dumps({"text": "walk"}).encode()
    first: dict[str, Any] = {}
    thread = threading.Thread(target=lambda: first.update(r=_request(blocking_server, "POST", "/api/generate", body)))
    thread.start()
    assert service.started.wait(5)
    status, headers, data = _request(blocking_server, "POST", "/api/generate", body)
    answer = json.loads(data)
    assert status == 429 and answer["queue"] == 1 and answer["limit"] == 0 and "busy" in answer["error"]
    assert headers.get("Retry-After")
    assert json.loads(_request(blocking_server, "GET", "/api/info")[2])["queue"] == {"pending": 1, "limit": 0}
    service.release.set()
    thread.join(10)
    assert first["r"][0] == 200 and json.loads(first["r"][2])["meta"]["queue_position"] == 0


def test_server_too_many_connections_503(tmp_path):
    server = ViewerServer(_BlockingService(tmp_path, 0), "127.0.0.1", 0, request_timeout=2.0, max_connections=1)
    server.start_in_thread()
    try:
        with socket.create_connection(("127.0.0.1", server.port), timeout=5):  # holds the only slot
            time.sleep(0.2)
            status, headers, data = _request(server, "GET", "/api/info")
            assert status == 503 and "busy" in json.loads(data)["error"]
        time.sleep(2.5)  # the silent connection times out and frees its slot
        assert _request(server, "GET", "/api/info")[0] == 200
    finally:
        server.shutdown()
        server.server_close()
