"""The viewer's HTTP server: static page + JSON API on the standard library's ThreadingHTTPServer.

Routes:
    ``GET /`` and ``GET /static/<file>``: the page (html, js, css shipped in the package).
    ``GET /api/info``: model status, listed files, slider ranges, skeleton.
    ``POST /api/generate`` (``application/json``): ``{text, gravity, wind_x, wind_y, seconds, seed, simulate}`` and
    optionally the sampling settings ``steps, eta, guidance, alpha, env_guidance, edit_t, foot_lock`` (left out:
    the model's ``sampling.json`` values, as ``simdiff generate``)
    → ``{joints, fps, parents, meta}``.
    ``POST /api/open?name=FILE`` (``application/octet-stream``, the file's bytes) → same.
    ``GET /api/files/<i>``: the i-th file named on the command line → same.
    ``HEAD`` answers like ``GET`` without the body.
Errors answer ``{"error": "one line"}``: 400 bad input (malformed or too deeply nested JSON
included), 408 a body that does not arrive within the socket timeout, 429 the generation queue
is full (with ``queue``: requests ahead, and ``Retry-After``), 503 no model or too many
connections.

Reliability: every connection has a socket timeout (:data:`REQUEST_TIMEOUT_S`), at most
:data:`MAX_CONNECTIONS` are served at once (more get 503 at once), generation requests wait in
a bounded queue (:class:`~simdiff.serve.service.MotionService`) and ask for at most
:data:`~simdiff.serve.params.MAX_STEPS` sampler steps.

Requests from other sites are refused: the ``Host`` header must name this server (against DNS
rebinding) and POSTs need a JSON/octet-stream content type plus a same-origin ``Origin``.
"""

from __future__ import annotations

import errno
import json
import re
import socket
import sys
import threading
import traceback
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from typing import Any, TextIO
from urllib.parse import parse_qs, urlsplit

from simdiff.errors import SimdiffError
from simdiff.serve.params import parse_generate
from simdiff.serve.service import ModelUnavailable, MotionService, QueueFull

REQUEST_TIMEOUT_S: float = 30.0
"""Seconds a connection may stay silent (request line, headers or body) before it is closed."""
MAX_CONNECTIONS: int = 32
"""Connections served at once; more are answered 503 without a thread."""
MAX_JSON_BYTES: int = 64 * 1024
MAX_UPLOAD_BYTES: int = 64 * 1024 * 1024
CONTENT_TYPES: dict[str, str] = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".css": "text/css; charset=utf-8",
}
LOOPBACK_NAMES: frozenset[str] = frozenset({"127.0.0.1", "localhost", "::1"})
_STATIC_NAME = re.compile(r"[a-z0-9_-]+\.(html|js|css)")


def _static_files() -> dict[str, bytes]:
    """The page's files, read once from the package: name → bytes."""
    folder = resources.files("simdiff.serve") / "static"
    return {entry.name: entry.read_bytes() for entry in folder.iterdir() if _STATIC_NAME.fullmatch(entry.name)}


class HttpError(Exception):
    """An answer other than 200, with a one-line message for the page."""

    def __init__(self, status: HTTPStatus, message: str) -> None:
        super().__init__(message)
        self.status = status


class ViewerHandler(BaseHTTPRequestHandler):
    """One request; the state lives on ``self.server`` (a :class:`ViewerServer`)."""

    server: "ViewerServer"
    server_version = "simdiff-serve"

    # -- routing -----------------------------------------------------------------------------

    def do_GET(self) -> None:  # noqa: N802 (http.server's naming)
        self._dispatch(self._get)

    def do_POST(self) -> None:  # noqa: N802
        self._dispatch(self._post)

    def do_HEAD(self) -> None:  # noqa: N802
        self._dispatch(self._get)

    def setup(self) -> None:
        """Apply the server's socket timeout to this connection (read and write)."""
        self.timeout = self.server.request_timeout
        super().setup()

    def _get(self, path: str, query: dict[str, list[str]]) -> None:
        if path in ("/", "/index.html"):
            self._static("index.html")
        elif path.startswith("/static/"):
            self._static(path[len("/static/"):])
        elif path == "/api/info":
            self._json(self.server.service.info())
        elif match := re.fullmatch(r"/api/files/(\d{1,6})", path):
            self._json(self.server.service.open_listed(int(match.group(1))))
        elif path == "/favicon.ico":
            self._send(HTTPStatus.NO_CONTENT, b"", "text/plain")
        else:
            raise HttpError(HTTPStatus.NOT_FOUND, f"no such page {path}")

    def _post(self, path: str, query: dict[str, list[str]]) -> None:
        self._check_origin()
        if path == "/api/generate":
            body = self._body("application/json", MAX_JSON_BYTES)
            try:
                request = json.loads(body.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                raise HttpError(HTTPStatus.BAD_REQUEST, f"request body is not valid JSON: {exc}") from None
            except RecursionError:
                raise HttpError(HTTPStatus.BAD_REQUEST, "request body is not valid JSON: nested too deeply") from None
            self._log_api(f"generate {request!r}"[:200])
            self._json(self.server.service.generate(parse_generate(request)))
        elif path == "/api/open":
            name = (query.get("name") or [""])[0]
            data = self._body("application/octet-stream", MAX_UPLOAD_BYTES)
            self._log_api(f"open {name!r} ({len(data)} bytes)")
            self._json(self.server.service.open_upload(name, data))
        else:
            raise HttpError(HTTPStatus.NOT_FOUND, f"no such endpoint {path}")

    def _dispatch(self, route: Any) -> None:
        try:
            self._check_host()
            parts = urlsplit(self.path)
            route(parts.path, parse_qs(parts.query))
        except HttpError as exc:
            self._error(exc.status, str(exc))
        except QueueFull as exc:
            self._error(HTTPStatus.TOO_MANY_REQUESTS, str(exc), {"queue": exc.waiting, "limit": exc.limit})
        except ModelUnavailable as exc:
            self._error(HTTPStatus.SERVICE_UNAVAILABLE, str(exc))
        except SimdiffError as exc:
            self._error(HTTPStatus.BAD_REQUEST, str(exc))
        except (BrokenPipeError, ConnectionResetError):
            self.close_connection = True
        except TimeoutError:
            self.close_connection = True
            self._error(HTTPStatus.REQUEST_TIMEOUT, f"no complete request within {self.server.request_timeout:g} s")
        except Exception as exc:  # a bug: keep serving, tell the page, log the traceback
            traceback.print_exc(file=self.server.log)
            self._error(HTTPStatus.INTERNAL_SERVER_ERROR, f"internal error: {type(exc).__name__}: {exc}")

    # -- checks ------------------------------------------------------------------------------

    def _check_host(self) -> None:
        """Refuse requests addressed to another name (DNS rebinding) unless bound to all interfaces."""
        host = self.headers.get("Host")
        if host is None or self.server.any_host:
            return
        name = urlsplit(f"//{host}").hostname or ""
        if name not in self.server.allowed_names:
            raise HttpError(HTTPStatus.FORBIDDEN, f"host {host!r} is not this server")

    def _check_origin(self) -> None:
        """A browser's cross-site POST carries a foreign ``Origin``: refuse it."""
        origin = self.headers.get("Origin")
        host = self.headers.get("Host")
        if origin is not None and host is not None and urlsplit(origin).netloc != host:
            raise HttpError(HTTPStatus.FORBIDDEN, f"cross-origin request from {origin!r} refused")

    def _body(self, content_type: str, limit: int) -> bytes:
        got = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
        if got != content_type:
            raise HttpError(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, f"expected Content-Type {content_type}, got {got or 'none'!r}")
        length = self.headers.get("Content-Length")
        if length is None or not length.isdigit():
            raise HttpError(HTTPStatus.LENGTH_REQUIRED, "Content-Length is required")
        if int(length) > limit:
            self.close_connection = True  # the unread body must not be taken for the next request
            raise HttpError(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"request of {int(length)} bytes is over the {limit}-byte limit")
        data = self.rfile.read(int(length))  # TimeoutError after the socket timeout: answered 408
        if len(data) < int(length):
            self.close_connection = True
            raise HttpError(HTTPStatus.BAD_REQUEST, f"request body ended after {len(data)} of {int(length)} bytes")
        return data

    # -- answers -----------------------------------------------------------------------------

    def _static(self, name: str) -> None:
        data = self.server.static.get(name)
        if data is None:
            raise HttpError(HTTPStatus.NOT_FOUND, f"no such file {name!r}")
        self._send(HTTPStatus.OK, data, CONTENT_TYPES["." + name.rsplit(".", 1)[-1]])

    def _json(self, value: Any, status: HTTPStatus = HTTPStatus.OK) -> None:
        self._send(status, json.dumps(value, separators=(",", ":"), allow_nan=False).encode("utf-8"), "application/json")

    def _error(self, status: HTTPStatus, message: str, extra: dict[str, Any] | None = None) -> None:
        line = " ".join(message.split()) or status.phrase
        self._log_api(f"{int(status)} {line}")
        headers = {"Retry-After": "5"} if status in (HTTPStatus.TOO_MANY_REQUESTS, HTTPStatus.SERVICE_UNAVAILABLE) else {}
        if status == HTTPStatus.REQUEST_TIMEOUT:
            headers["Connection"] = "close"
        try:
            self._send(status, json.dumps({"error": line, **(extra or {})}).encode("utf-8"), "application/json", headers)
        except (BrokenPipeError, ConnectionResetError, TimeoutError):
            self.close_connection = True

    def _send(self, status: HTTPStatus, data: bytes, content_type: str, headers: dict[str, str] | None = None) -> None:
        self.send_response(status)
        for key, value in (headers or {}).items():
            self.send_header(key, value)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(data)

    def _log_api(self, text: str) -> None:
        if self.server.verbose:
            print(f"[{self.log_date_time_string()}] {self.command} {text}", file=self.server.log, flush=True)

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002 (base class signature)
        """Silence the per-request access log; API calls are logged by ``_log_api``."""


class ViewerServer(ThreadingHTTPServer):
    """The viewer's server; serve with ``serve_forever()`` or :meth:`start_in_thread`.

    Args:
        service: the API's back end.
        host: address to bind (default loopback only).
        port: TCP port; 0 picks a free one (see :attr:`url`).
        verbose: log API calls and errors to ``log``.
        log: where logs go (default stderr).
        request_timeout: socket timeout of each connection in seconds.
        max_connections: connections served at once (more are answered 503 and closed).
    Raises:
        SimdiffError: the address cannot be bound (port in use, unknown host).
    """

    daemon_threads = True

    def __init__(self, service: MotionService, host: str = "127.0.0.1", port: int = 8765, *,
                 verbose: bool = False, log: TextIO | None = None, request_timeout: float = REQUEST_TIMEOUT_S,
                 max_connections: int = MAX_CONNECTIONS) -> None:
        if not request_timeout > 0 or max_connections < 1:
            raise SimdiffError(f"request_timeout must be > 0 and max_connections ≥ 1, got {request_timeout}, {max_connections}")
        self.request_timeout = float(request_timeout)
        self._slots = threading.BoundedSemaphore(max_connections)
        self.address_family = socket.AF_INET6 if ":" in host else socket.AF_INET
        try:
            super().__init__((host, port), ViewerHandler)
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                raise SimdiffError(f"port {port} on {host} is already in use (try --port 0 for a free one)") from None
            raise SimdiffError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
        self.service = service
        self.verbose = verbose
        self.log = log if log is not None else sys.stderr
        self.static = _static_files()
        self.any_host = host in ("", "0.0.0.0", "::")
        self.allowed_names = LOOPBACK_NAMES | {host, socket.gethostname()}

    def process_request(self, request: Any, client_address: Any) -> None:
        """Serve the connection in a thread if a slot is free, else answer 503 and close it."""
        if not self._slots.acquire(blocking=False):
            try:
                request.settimeout(1.0)
                body = b'{"error": "the server is busy: too many connections; try again in a moment"}'
                request.sendall(b"HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\n"
                                b"Retry-After: 5\r\nConnection: close\r\nContent-Length: "
                                + str(len(body)).encode() + b"\r\n\r\n" + body)
            except OSError:
                pass
            self.shutdown_request(request)
            return
        super().process_request(request, client_address)

    def process_request_thread(self, request: Any, client_address: Any) -> None:
        try:
            super().process_request_thread(request, client_address)
        finally:
            self._slots.release()

    @property
    def port(self) -> int:
        """The bound port (useful after binding port 0)."""
        return int(self.server_address[1])

    @property
    def url(self) -> str:
        """The page's address, e.g. ``http://127.0.0.1:8765/``."""
        host = str(self.server_address[0])
        if self.any_host:
            host = "127.0.0.1"
        return f"http://[{host}]:{self.port}/" if ":" in host else f"http://{host}:{self.port}/"

    def start_in_thread(self) -> threading.Thread:
        """Serve from a daemon thread (tests, notebooks); stop with ``shutdown()`` then ``server_close()``."""
        thread = threading.Thread(target=self.serve_forever, name="simdiff-serve", daemon=True)
        thread.start()
        return thread
