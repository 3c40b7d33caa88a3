"""``simdiff serve`` under abuse: slow senders, abandoned generations, large uploads, malformed requests.

The server runs in a thread on port 0 with a stand-in generator (:class:`~simdiff.serve.testing.SlowGenerator`:
no model, a fixed time per sampler step) and limits made small, so each case takes about a second.
"""

from __future__ import annotations

import io
import json
import socket
import threading
import time
import tracemalloc
import urllib.error
import urllib.request
from collections.abc import Iterator
from typing import Any, Self

import numpy as np
import pytest

from simdiff.errors import NonFiniteResult
from simdiff.motion import synthetic
from simdiff.serve import server as server_module
from simdiff.serve import service as service_module
from simdiff.serve.testing import SlowGenerator, slow_service

DEADLINE_S = 1.0  # whole-request deadline of the test servers
GRACE_S = 0.2  # how long a slow sender keeps its slot against newcomers


@pytest.fixture()
def make_server(tmp_path, monkeypatch) -> Iterator[Any]:
    """Build servers over a :class:`SlowGenerator` service; all are shut down after the test."""
    monkeypatch.setattr(server_module, "EVICT_GRACE_S", GRACE_S)
    made = []

    def make(generator: SlowGenerator | None = None, *, max_queue: int = 4, max_connections: int | None = None,
             files: Any = ()) -> server_module.ViewerServer:
        service = slow_service(tmp_path / "no-model", generator, max_queue=max_queue, files=files)
        log = io.StringIO()
        limits = {} if max_connections is None else {"max_connections": max_connections}
        srv = server_module.ViewerServer(service, "127.0.0.1", 0, log=log, request_timeout=DEADLINE_S, **limits)
        srv.start_in_thread()
        made.append(srv)
        return srv

    yield make
    for srv in made:
        srv.shutdown()
        srv.server_close()


def connect(srv: server_module.ViewerServer) -> socket.socket:
    return socket.create_connection(("127.0.0.1", srv.port), timeout=10)


def read_answer(sock: socket.socket) -> tuple[int, dict[str, str], bytes]:
    """(status, headers, body) of the answer on ``sock``, read to the end of the connection."""
    data = b""
    try:
        while chunk := sock.recv(65536):
            data += chunk
    except ConnectionResetError:
        pass
    head, _, body = data.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    status = int(lines[0].split()[1]) if lines[0].startswith("HTTP/") else 0
    headers = dict(line.split(": ", 1) for line in lines[1:] if ": " in line)
    return status, headers, body


def raw(srv: server_module.ViewerServer, data: bytes) -> tuple[int, dict[str, str], bytes]:
    """Send ``data`` as it is, answer of the server."""
    with connect(srv) as sock:
        sock.sendall(data)
        return read_answer(sock)


def post(path: str, body: bytes, content_type: str = "application/json", extra: str = "") -> bytes:
    return (f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: {content_type}\r\n"
            f"Content-Length: {len(body)}\r\n{extra}\r\n").encode() + body


def generate_body(**fields: Any) -> bytes:
    return json.dumps({"text": "a person walks", "seconds": 1.0, **fields}).encode()


def call(srv: server_module.ViewerServer, path: str, body: bytes | None = None,
         content_type: str = "application/json") -> tuple[int, Any]:
    request = urllib.request.Request(srv.url + path.lstrip("/"), data=body,
                                     headers={"Content-Type": content_type} if body is not None else {})
    try:
        with urllib.request.urlopen(request, timeout=30) as response:
            return response.status, json.loads(response.read())
    except urllib.error.HTTPError as exc:
        return exc.code, json.loads(exc.read())


def one_json_line(body: bytes) -> str:
    """The ``error`` of a one-line JSON error answer."""
    text = body.decode("utf-8")
    assert "\n" not in text.strip() and "Traceback" not in text, text[:200]
    answer = json.loads(text)
    assert set(answer) >= {"error"} and "\n" not in answer["error"]
    return answer["error"]


def wait_for(condition: Any, timeout: float = 5.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


# -- slow clients ------------------------------------------------------------------------------


def test_trickling_client_is_cut_off_at_the_whole_request_deadline(make_server):
    """One byte every 0.05 s never trips a per-read timeout; the whole-request deadline still ends it (408)."""
    srv = make_server()
    start = time.monotonic()
    answer = b""
    with connect(srv) as sock:
        sock.setblocking(False)
        for byte in b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: " + b"a" * 200:
            try:
                answer = sock.recv(65536)
                break  # the server answered (or closed)
            except BlockingIOError:
                pass
            except OSError:
                break
            sock.send(bytes([byte]))
            time.sleep(0.05)
        cut_off_s = time.monotonic() - start
        sock.settimeout(5)
        answer += read_answer_bytes(sock)
    assert cut_off_s < DEADLINE_S + 0.5
    if answer:  # a reset may beat the answer to the client; when it arrives it is a 408 JSON line
        head, _, body = answer.partition(b"\r\n\r\n")
        assert head.split()[1] == b"408" and "within 1 s" in one_json_line(body)


def read_answer_bytes(sock: socket.socket) -> bytes:
    data = b""
    try:
        while chunk := sock.recv(65536):
            data += chunk
    except OSError:
        pass
    return data


def test_slow_senders_make_room_for_a_newcomer(make_server):
    """All slots held by silent connections: a newcomer takes the oldest one's slot (that one gets 408)."""
    srv = make_server(max_connections=4)
    silent = [connect(srv) for _ in range(4)]
    try:
        for sock in silent:
            sock.sendall(b"GET /api/info HTTP/1.1\r\n")
        time.sleep(GRACE_S + 0.1)
        start = time.monotonic()
        status, answer = call(srv, "/api/info")
        assert status == 200 and answer["queue"]["limit"] == 4
        assert time.monotonic() - start < 2.0  # at once, not after the silent ones' deadline
        status, _, body = read_answer(silent[0])  # the oldest was closed for the newcomer
        assert status == 408 and "make room" in one_json_line(body)
    finally:
        for sock in silent:
            sock.close()


class _Slowloris:
    """``count`` connections that send a request one byte every ``every`` s, reconnecting ``reconnect`` s after
    the server closes one."""

    def __init__(self, srv: server_module.ViewerServer, count: int, every: float = 0.1, reconnect: float = 0.3):
        self.srv, self.every, self.reconnect = srv, every, reconnect
        self.head = b"POST /api/generate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n" \
                    b"Content-Length: 100\r\n\r\n" + b" " * 100
        self.socks: list[tuple[socket.socket | None, int, float]] = [(None, 0, 0.0)] * count
        self.stop = threading.Event()
        self.closed = 0
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self.stop.is_set():
            now = time.monotonic()
            for i, (sock, sent, retry_at) in enumerate(self.socks):
                if sock is None:
                    if now >= retry_at:
                        try:
                            sock = socket.create_connection(("127.0.0.1", self.srv.port), timeout=1)
                        except OSError:
                            self.socks[i] = (None, 0, now + self.reconnect)
                            continue
                        sock.setblocking(False)
                        self.socks[i] = (sock, 0, 0.0)
                    continue
                try:
                    sock.recv(4096)  # an answer (408, 503) or the end: the server is done with it
                    done = True
                except BlockingIOError:
                    done = False
                except OSError:
                    done = True
                if not done:
                    try:
                        sock.send(self.head[sent % len(self.head):sent % len(self.head) + 1])
                        self.socks[i] = (sock, sent + 1, 0.0)
                    except OSError:
                        done = True
                if done:
                    sock.close()
                    self.closed += 1
                    self.socks[i] = (None, 0, now + self.reconnect)
            self.stop.wait(self.every)
        for sock, _, _ in self.socks:
            if sock is not None:
                sock.close()

    def __enter__(self) -> Self:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        self.thread.join(5)


def abandon_generations(srv: server_module.ViewerServer, count: int, steps: int) -> None:
    """Send ``count`` long generation requests and close their connections once they are queued or running."""
    socks = [connect(srv) for _ in range(count)]
    for sock in socks:
        sock.sendall(post("/api/generate", generate_body(steps=steps)))
    assert wait_for(lambda: srv.service.queue_status()["pending"] >= count)
    for sock in socks:
        sock.close()


def test_normal_requests_are_answered_under_slow_clients_and_abandoned_generations(make_server):
    """40 trickling clients (reconnecting when dropped) and 3 abandoned 10 s generations: a page still gets its
    info and a generation within seconds."""
    generator = SlowGenerator(step_s=0.05)
    srv = make_server(generator)
    abandon_generations(srv, 3, steps=200)  # 3 × 10 s of sampling if nobody noticed
    with _Slowloris(srv, 40) as attack:
        time.sleep(DEADLINE_S + 0.5)  # every slot taken by a slow sender, some of them cut off already
        start = time.monotonic()
        status, info = call(srv, "/api/info")
        info_s = time.monotonic() - start
        start = time.monotonic()
        status_gen, motion = call(srv, "/api/generate", generate_body(steps=2))
        generate_s = time.monotonic() - start
        assert attack.closed > 0  # slow senders were cut off (deadline or a newcomer)
    print(f"under 40 slow clients + 3 abandoned generations: info {info_s:.3f} s, generate {generate_s:.3f} s")
    assert status == 200 and info["model"]["path"]
    assert status_gen == 200 and np.asarray(motion["joints"]).shape == (20, 22, 3)
    assert info_s < 3.0 and generate_s < 5.0
    assert generator.finished == 1  # the abandoned ones never ran to the end


# -- abandoned generations ---------------------------------------------------------------------


def test_abandoned_generations_free_the_queue(make_server):
    generator = SlowGenerator(step_s=0.05)
    srv = make_server(generator, max_queue=4)
    socks = [connect(srv) for _ in range(5)]  # one running, four queued: 5 × 10 s
    socks[0].sendall(post("/api/generate", generate_body(steps=200)))
    assert wait_for(lambda: generator.started == 1)
    for sock in socks[1:]:
        sock.sendall(post("/api/generate", generate_body(steps=200)))
    assert wait_for(lambda: srv.service.queue_status()["pending"] == 5)
    status, answer = call(srv, "/api/generate", generate_body(steps=2))
    assert status == 429 and answer["queue"] == 5
    start = time.monotonic()
    for sock in socks[::-1]:  # the queued ones first, then the running one
        sock.close()
    assert wait_for(lambda: srv.service.queue_status()["pending"] == 0, timeout=2.0)
    freed_s = time.monotonic() - start
    assert freed_s < 2.0
    assert generator.started == 1 and generator.finished == 0  # the queued ones never started
    status, answer = call(srv, "/api/generate", generate_body(steps=2))
    assert status == 200 and answer["meta"]["queue_position"] == 0


class _RefusingGenerator(SlowGenerator):
    """A generator that checks its own sample and refuses a non-finite one."""

    def generate(self, *args: Any, **kwargs: Any) -> Any:
        raise NonFiniteResult("sampling gave non-finite values (guidance 20); try settings nearer the model's defaults")


@pytest.mark.parametrize("generator", [SlowGenerator(step_s=0.0, value=float("nan")), _RefusingGenerator()],
                         ids=["nan-sample", "generator-refuses"])
def test_non_finite_generation_is_a_422(make_server, generator):
    srv = make_server(generator)
    status, answer = call(srv, "/api/generate", generate_body(steps=2))
    assert status == 422 and "non-finite values" in answer["error"]


# -- uploads -----------------------------------------------------------------------------------


def npy_bytes(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def test_upload_over_the_limit_is_413_before_its_body_is_read(make_server):
    srv = make_server()
    limit = server_module.MAX_UPLOAD_BYTES
    with connect(srv) as sock:  # headers only: the answer comes without the body
        sock.sendall(f"POST /api/open?name=big.npy HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: "
                     f"application/octet-stream\r\nContent-Length: {limit + 1}\r\n\r\n".encode())
        sock.settimeout(2 * DEADLINE_S)
        status, _, body = read_answer(sock)
    assert status == 413 and f"{limit}-byte limit" in one_json_line(body)


def test_upload_over_the_limit_is_a_413_the_client_sees(make_server, monkeypatch):
    monkeypatch.setattr(server_module, "MAX_UPLOAD_BYTES", 1 << 20)
    srv = make_server()
    status, answer = call(srv, "/api/open?name=big.npy", b"\0" * (3 << 20), "application/octet-stream")
    assert status == 413 and "limit" in answer["error"]


def test_motion_over_the_frame_limit_is_413_and_answers_are_bounded(make_server, monkeypatch):
    monkeypatch.setattr(service_module, "MAX_OPEN_FRAMES", 2000)
    srv = make_server()
    walk = synthetic.walk(2001)
    status, answer = call(srv, "/api/open?name=long.npy", npy_bytes(walk), "application/octet-stream")
    assert status == 413 and "2001 frames" in answer["error"] and "2000 frames" in answer["error"]
    status, answer = call(srv, "/api/open?name=ok.npy", npy_bytes(walk[:2000]), "application/octet-stream")
    assert status == 200 and answer["meta"]["frames"] == 2000


def test_largest_upload_takes_bounded_memory(make_server):
    """A motion at the frame limit as float64 features (the largest .npy the limit lets through): the server's
    peak Python/numpy memory stays a small multiple of the file and the answer (no 1.8 GB, 129 MB answers)."""
    srv = make_server()
    frames = service_module.MAX_OPEN_FRAMES
    from simdiff.motion.features import joints_to_features

    walk = synthetic.walk(frames + 1)
    data = npy_bytes(joints_to_features(walk).astype(np.float64))
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        request = urllib.request.Request(srv.url + "api/open?name=features.npy", data=data,
                                         headers={"Content-Type": "application/octet-stream"})
        with urllib.request.urlopen(request, timeout=60) as response:
            answer = response.read()
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    print(f"upload of {len(data) / 2**20:.1f} MiB ({frames} frames): peak {peak / 2**20:.0f} MiB, "
          f"answer {len(answer) / 2**20:.1f} MiB")
    assert json.loads(answer)["meta"]["frames"] == frames
    assert len(answer) < 8 * 2**20
    assert peak < 12 * len(data)


def test_declared_upload_size_takes_no_memory_until_it_arrives(make_server):
    """A client that declares the largest upload and sends 1 KiB costs a 64 KiB chunk, not a 32 MiB buffer."""
    srv = make_server()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        with connect(srv) as sock:
            sock.sendall(f"POST /api/open?name=big.npy HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/"
                         f"octet-stream\r\nContent-Length: {server_module.MAX_UPLOAD_BYTES}\r\n\r\n".encode()
                         + b"\0" * 1024)
            time.sleep(0.3)
            peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    assert peak < 2 * 2**20


def test_uploads_beyond_the_readers_are_503(make_server):
    srv = make_server()
    readers = srv.service._uploads  # every reader busy
    for _ in range(service_module.UPLOADS_AT_ONCE):
        assert readers.acquire(blocking=False)
    try:
        status, answer = call(srv, "/api/open?name=walk.npy", npy_bytes(synthetic.walk(20)), "application/octet-stream")
        assert status == 503 and "busy reading" in answer["error"]
    finally:
        for _ in range(service_module.UPLOADS_AT_ONCE):
            readers.release()
    status, answer = call(srv, "/api/open?name=walk.npy", npy_bytes(synthetic.walk(20)), "application/octet-stream")
    assert status == 200 and answer["meta"]["frames"] == 20


# -- malformed requests ------------------------------------------------------------------------

BAD_GENERATE = [
    ({"text": "walk", "seconds": 0.1}, "seconds must be in [0.5, 9.8], got 0.1"),
    ({"text": "walk", "seconds": 0.49}, "seconds must be in [0.5, 9.8]"),
    ({"text": "walk", "seconds": "2"}, "seconds must be a finite number"),
    ({"text": "walk", "gravity": [1]}, "gravity must be a finite number"),
    ({"text": "walk", "gravity": True}, "gravity must be a finite number"),
    ({"text": "walk", "wind_x": None}, "wind_x must be a finite number"),
    ({"text": "walk", "seed": "1"}, "seed must be an integer"),
    ({"text": "walk", "seed": 10**30}, "seed must be a non-negative integer"),
    ({"text": "walk", "steps": [2]}, "steps must be an integer"),
    ({"text": "walk", "steps": 10**35}, "steps must be in [1, 200]"),
    ({"text": "walk", "gravity": -10**35}, "gravity must be in [-20, -1]"),
    ({"text": "walk", "simulate": 1}, "simulate must be true or false"),
    ({"text": 5}, "text must be a non-empty prompt"),
    ({"text": ["walk"]}, "text must be a non-empty prompt"),
    ({"text": "walk", "x" * 5000: 1}, "unknown field"),
]


@pytest.mark.parametrize("body, needle", BAD_GENERATE)
def test_bad_generate_field_is_a_400(make_server, body, needle):
    srv = make_server()
    status, _, answer = raw(srv, post("/api/generate", json.dumps(body).encode()))
    error = one_json_line(answer)
    assert status == 400 and needle in error and len(error) < 400, error


@pytest.mark.parametrize("text, needle", [
    (b'{"text": "walk", "gravity": NaN}', "NaN"),
    (b'{"text": "walk", "gravity": Infinity}', "Infinity"),
    (b'{"text": "walk", "wind_x": -Infinity}', "-Infinity"),
    (b'{"text": "walk", "gravity": 1e400}', "out of range"),
    (b'{"text": "walk", "seed": ' + b"9" * 5000 + b"}", "out of range"),
    (b'{"text": "walk\xff"}', "not valid UTF-8"),
    (b'{"text": "\\ud800"}', "lone surrogate"),
    (b"[]", "must be a JSON object"),
    (b'"walk"', "must be a JSON object"),
    (b"null", "must be a JSON object"),
    (b"", "not valid JSON"),
    (b"[" * 30000, "nested too deeply"),
])
def test_bad_json_is_a_400(make_server, text, needle):
    srv = make_server()
    status, _, answer = raw(srv, post("/api/generate", text))
    assert status == 400 and needle in one_json_line(answer)


@pytest.mark.parametrize("request_bytes, expected, needle", [
    (b"POST /api/generate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n\r\n{}", 411,
     "Content-Length is required"),
    (post("/api/generate", b"", extra="Content-Length: -5\r\n").replace(b"Content-Length: 0\r\n", b""), 400,
     "Content-Length must be one whole number"),
    (post("/api/generate", b"", extra="Content-Length: ten\r\n").replace(b"Content-Length: 0\r\n", b""), 400,
     "Content-Length must be one whole number"),
    (post("/api/generate", b"{}", extra="Content-Length: 3\r\n"), 400, "Content-Length must be one whole number"),
    ((b"POST /api/generate HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
      b"Transfer-Encoding: chunked\r\n\r\n2\r\n{}\r\n0\r\n\r\n"), 411, "chunked"),
    (b"GET /api/files/abc HTTP/1.1\r\n\r\n", 400, "file index must be a whole number"),
    (b"GET /api/files/-1 HTTP/1.1\r\n\r\n", 400, "file index must be a whole number"),
    (b"GET /api/files/99999999999999999999 HTTP/1.1\r\n\r\n", 400, "file index must be a whole number"),
    (b"GET /api/files/5 HTTP/1.1\r\n\r\n", 400, "no listed file 5"),
    (b"GET /static/../server.py HTTP/1.1\r\n\r\n", 404, "no such file"),
    (b"GET /static/..%2fserver.py HTTP/1.1\r\n\r\n", 404, "no such file"),
    (b"GET /../../etc/passwd HTTP/1.1\r\n\r\n", 404, "no such page"),
    (b"GET /api/info?" + b"&".join(b"a=%d" % i for i in range(100)) + b" HTTP/1.1\r\n\r\n", 400,
     "bad request target"),
    (b"GET /" + b"a" * 10000 + b" HTTP/1.1\r\n\r\n", 414, "request line over"),
    (b"GET / HTTP/1.1\r\nX-Big: " + b"a" * 40000 + b"\r\n\r\n", 431, "headers are over"),
    (b"GET / HTTP/1.1\r\n" + b"".join(b"X-%d: a\r\n" % i for i in range(120)) + b"\r\n", 431, "Too many headers"),
    (b"GET / HTTP/1.1\r\nHost: [\r\n\r\n", 400, "bad Host header"),
    (b"GET /api/info HTTP/1.1\r\nHost: evil.example\r\n\r\n", 403, "is not this server"),
    (b"HELLO\r\n\r\n", 400, "Bad request syntax"),
    (b"GET / HTTP/x\r\n\r\n", 400, "Bad request version"),
    (b"GET /\r\n\r\n", 400, "HTTP/0.9"),
    (b"GET / HTTP/2.0\r\n\r\n", 505, "Invalid HTTP version"),
    (post("/api/open?name=" + "a" * 300 + ".npy", b"x", "application/octet-stream"), 400, "the limit is 255"),
    (post("/api/open?name=a%00b.npy", b"x", "application/octet-stream"), 400, "control characters"),
    (post("/api/open?name=a.npy&name=b.npy", b"x", "application/octet-stream"), 400, "give one name"),
    (post("/api/open?name=a.npy", b"not an npy file", "application/octet-stream"), 400, "a.npy"),
    (post("/api/open?name=a.bvh", b"HIERARCHY\nROOT", "application/octet-stream"), 400, "a.bvh"),
    (post("/api/generate", b"{}", "text/plain"), 415, "expected Content-Type application/json"),
])
def test_bad_request_is_one_json_line_with_a_4xx(make_server, request_bytes, expected, needle):
    srv = make_server()
    status, headers, answer = raw(srv, request_bytes)
    error = one_json_line(answer)
    assert status == expected and needle in error, (status, error)
    assert headers["Content-Type"] == "application/json"
    assert "simdiff-serve-" not in error and "/tmp" not in error  # never a temporary path
    assert "Traceback" not in srv.log.getvalue()


@pytest.mark.parametrize("method", ["OPTIONS", "PUT", "DELETE", "PATCH", "TRACE", "CONNECT", "BREW"])
def test_other_methods_are_405_with_allow(make_server, method):
    srv = make_server()
    target = "127.0.0.1:443" if method == "CONNECT" else "/api/info"
    status, headers, answer = raw(srv, f"{method} {target} HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                       f"Content-Length: 2\r\n\r\n{{}}".encode())
    assert status == 405 and headers["Allow"] == "GET, HEAD, POST"
    assert "not allowed" in one_json_line(answer)


def test_internal_error_is_one_json_line_and_one_log_line(make_server, monkeypatch):
    srv = make_server()

    def broken() -> dict[str, Any]:
        raise RuntimeError("boom in /tmp/simdiff-serve-abc/secret.npy\nsecond line")

    monkeypatch.setattr(srv.service, "info", broken)
    status, _, answer = raw(srv, b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    error = one_json_line(answer)
    assert status == 500 and "RuntimeError" in error and "/tmp" not in error
    log = srv.log.getvalue().strip().splitlines()
    assert len(log) == 1 and "RuntimeError: boom" in log[0] and "Traceback" not in log[0]
    assert raw(srv, b"GET / HTTP/1.1\r\n\r\n")[0] == 200  # still serving
