"""The viewer's HTTP server: static page + JSON API on the standard library's ThreadingHTTPServer.

Routes:
    ``GET /`` and ``GET /static/<file>``: the page (html, js, css shipped in the package; three.js in ``vendor/three``).
    ``GET /api/info``: model status, listed files, slider ranges and limits, skeleton.
    ``POST /api/generate`` (``application/json``): ``{text, gravity, wind_x, wind_y, seconds, seed, simulate}``, the
    optional sampling settings ``steps, eta, guidance, guidance_min_t, alpha, env_guidance, edit_t, foot_lock,
    flight_passes`` (left out: the model's ``sampling.json`` values, as ``simdiff generate``) and ``pin_start``, ``pin_end``: a motion's number
    whose first (last) pose it starts (ends) in (``meta.keyframe_error_cm``) → ``{joints, fps, parents, meta, motion, body}``.
    ``POST /api/edit`` (JSON): ``{source, gravity, wind_x, wind_y, seed, text}``: motion ``source`` re-played under φ as
    ``simdiff edit`` → same; ``POST /api/timeline`` (JSON): ``{segments: [{text, seconds, gravity?, wind?: [x, y]}],
    seed}``, checked as a ``generate --timeline`` file → its one motion, same (both also take the sampling settings).
    ``POST /api/open?name=FILE`` (``application/octet-stream``, the file's bytes) → same.
    ``GET /api/files/<i>``: the i-th file named on the command line → same.
    ``GET /api/body/<n>.glb`` (``body`` of an answer): that motion's skinned body, a ``model/gltf-binary`` file.
    ``HEAD`` answers like ``GET`` without the body. An answer's ``motion`` numbers it; the last few motions' joints
    stay on the server, so ``source`` and the pins name a motion shown without sending it (:mod:`simdiff.serve.edits`).

Every error is one JSON line ``{"error": "..."}``, never an HTML page, a traceback or a temporary path: 400 bad input
(malformed, non-object, too deeply nested or non-UTF-8 JSON; ``NaN``, ``Infinity``, out-of-range numbers or wrong
types in any field; unknown fields; a bad upload name or file, file index, motion number, timeline, pinned pose,
``Content-Length``, ``Host`` or request line); 403 a foreign ``Host`` (DNS rebinding) or ``Origin`` (cross-site POST);
404 no such page, file or endpoint; 405 a method other than GET, HEAD and POST (with ``Allow: GET, HEAD, POST``); 408
the request did not arrive within its deadline, or was closed to make room for another; 411 a POST without
``Content-Length`` (chunked transfer encoding is not accepted); 413 a body over its limit (answered before it is read)
or a motion over ``MAX_OPEN_FRAMES`` frames; 414 a request line over :data:`MAX_REQUEST_LINE`; 415 the wrong
``Content-Type``; 422 the sampler produced non-finite values with these settings; 429 the generation queue is full
(with ``queue``: requests ahead, ``limit``, and ``Retry-After``); 431 request line and headers over
:data:`MAX_HEAD_BYTES` or over 100 header lines; 500 a bug in the server (the answer names the exception type, the log
gets one line); 503 no model, or every connection slot is serving a request, or other uploads are being read (with
``Retry-After``); 505 an HTTP version other than 1.x.

Limits (module constants, read when a server is built, so tests can set them small):

* :data:`REQUEST_DEADLINE_S` for a whole request, request line + headers + body, however slowly it trickles in
  (a body gets :data:`BODY_SECONDS_PER_MIB` more per MiB); :data:`WRITE_TIMEOUT_S` per write of an answer.
* :data:`MAX_CONNECTIONS` connections at once. When all are taken, the one that has been sending its request
  the longest, for over :data:`EVICT_GRACE_S`, is closed (408) to make room; when none is, the newcomer gets
  503. Slow senders therefore hold no slot a newcomer needs, and none past the deadline.
* :data:`MAX_REQUEST_LINE` and :data:`MAX_HEAD_BYTES` for the request line and headers, :data:`MAX_JSON_BYTES`
  for a JSON body, :data:`MAX_UPLOAD_BYTES` for an upload (copied to a temporary file as it arrives, then read
  by at most :data:`~simdiff.serve.service.UPLOADS_AT_ONCE` readers at a time), and an opened motion of at most
  :data:`~simdiff.serve.service.MAX_OPEN_FRAMES` frames (10 minutes: an answer of at most about 6 MB, its body about 5 MB).
* Generations, re-plays and timelines wait in one bounded queue (:class:`~simdiff.serve.service.MotionService`), ask
  for at most :data:`~simdiff.serve.params.MAX_STEPS` sampler steps, :data:`~simdiff.serve.params.MAX_REPLAY_FRAMES`
  frames re-played, :data:`~simdiff.serve.params.MAX_TIMELINE_SEGMENTS` timeline segments, and are dropped, waiting
  or at the next sampler step, when their client closes its connection.

Requests from other sites are refused: the ``Host`` header must name this server (against DNS
rebinding) and POSTs need a JSON/octet-stream content type plus a same-origin ``Origin``.
"""

from __future__ import annotations

import errno
import json
import socket
import sys
import tempfile
import threading
import traceback
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, BinaryIO, TextIO
from urllib.parse import parse_qs, urlsplit

from simdiff.errors import NonFiniteResult, SimdiffError
from simdiff.serve.connections import (
    HeadTooLarge,
    RequestReader,
    Slots,
    linger,
    peer_closed,
)
from simdiff.serve.edits import POSTS
from simdiff.serve.service import (
    MAX_OPEN_FRAMES,
    GenerationCancelled,
    ModelUnavailable,
    MotionService,
    MotionTooLong,
    QueueFull,
    UploadsBusy,
)
from simdiff.serve.wire import (
    BUSY_ANSWER,
    CONTENT_TYPES,
    EVICTED_ANSWER,
    GLB_TYPE,
    HttpError,
    content_length,
    numbered,
    one_line,
    parse_json,
    quote,
    static_files,
)

REQUEST_DEADLINE_S: float = 10.0
"""Seconds for a whole request (request line, headers and body) to arrive, however slowly it trickles in."""
BODY_SECONDS_PER_MIB: float = 1.0
"""Extra deadline per MiB of declared body: an upload must arrive at 1 MiB/s or faster."""
WRITE_TIMEOUT_S: float = 30.0
"""Seconds one write of an answer may take before the connection is dropped."""
MAX_CONNECTIONS: int = 32
"""Connections served at once (see :data:`EVICT_GRACE_S`); more are answered 503 without a thread."""
EVICT_GRACE_S: float = 1.0
"""A connection still sending its request after this many seconds may be closed (408) for a newcomer."""
MAX_REQUEST_LINE: int = 8 * 1024
"""Longest request line (method, URL, version) in bytes; longer: 414."""
MAX_HEAD_BYTES: int = 32 * 1024
"""Longest request line plus headers in bytes; longer: 431."""
MAX_JSON_BYTES: int = 64 * 1024
"""Largest JSON body (``/api/generate``, ``/api/edit``, ``/api/timeline``); larger: 413."""
MAX_UPLOAD_BYTES: int = 32 * 1024 * 1024
"""Largest ``POST /api/open`` upload (a 10-minute motion is 3 MB of float32 joints, 13 MB of features, a few
MB to tens of MB of BVH text); larger: 413 before the body is read."""
MAX_QUERY_FIELDS: int = 16
"""Most ``name=value`` pairs in a query string; more: 400."""
DRAIN_BYTES: int = 64 * 1024
"""An unread body up to this size is read and dropped before an error answer, so that the client sees it."""
LINGER_S: float = 2.0
"""After an error answer to a larger unread body: seconds its rest is drained (not kept) before closing."""
ALLOWED_METHODS: str = "GET, HEAD, POST"
LOOPBACK_NAMES: frozenset[str] = frozenset({"127.0.0.1", "localhost", "::1"})


class ViewerHandler(BaseHTTPRequestHandler):
    """One connection (one request: HTTP/1.0); the state lives on ``self.server`` (a :class:`ViewerServer`)."""

    server: ViewerServer
    server_version = "simdiff-serve"

    def version_string(self) -> str:
        return self.server_version  # no Python version in the Server header

    # -- reading a request ---------------------------------------------------------------------

    def setup(self) -> None:
        """Read through a :class:`~simdiff.serve.connections.RequestReader` (whole-request deadline)."""
        super().setup()
        self.rfile.close()
        self.rfile = RequestReader(self.connection)  # type: ignore[assignment]
        self._linger = False

    def handle_one_request(self) -> None:
        """Read and answer one request; every failure is answered as one JSON line (or the connection closed)."""
        self.command, self.request_version, self.requestline, self.path = "", "HTTP/1.0", "", ""
        self._reading, self._answered, self._head_read, self._body_read = True, False, False, False
        reader: RequestReader = self.rfile  # type: ignore[assignment]
        reader.start(self.server.request_timeout, MAX_HEAD_BYTES)
        try:
            self.raw_requestline = reader.readline(MAX_REQUEST_LINE + 1)
            if not self.raw_requestline:
                self.close_connection = True
                return
            if len(self.raw_requestline) > MAX_REQUEST_LINE:
                raise HttpError(HTTPStatus.REQUEST_URI_TOO_LONG, f"request line over {MAX_REQUEST_LINE} bytes")
            if not self.parse_request():
                return  # answered by send_error
            reader.end_head()
            self._head_read = True
            if self.request_version == "HTTP/0.9":
                self.request_version = "HTTP/1.0"
                raise HttpError(HTTPStatus.BAD_REQUEST, "HTTP/0.9 requests are not supported")
            method = getattr(self, f"do_{self.command}", None)
            if method is None:
                raise HttpError(HTTPStatus.METHOD_NOT_ALLOWED,
                                f"method {quote(self.command, 30)} is not allowed: use {ALLOWED_METHODS}")
            method()
            self.wfile.flush()
        except HttpError as exc:
            self._error(exc.status, str(exc))
        except HeadTooLarge:
            self._error(HTTPStatus.REQUEST_HEADER_FIELDS_TOO_LARGE,
                        f"request line and headers are over {MAX_HEAD_BYTES} bytes")
        except TimeoutError:
            self._timed_out()
        except OSError:  # the client went away, or its slot went to a newcomer
            self.close_connection = True

    def _request_complete(self) -> None:
        """The whole request is read: the slot can no longer go to a newcomer; writes get their own timeout."""
        if self._reading:
            self._reading = False
            if not self.server.slots.done_reading(self.connection):
                raise ConnectionAbortedError("the connection was closed to make room for another")
            self.connection.settimeout(self.server.write_timeout)

    def _body(self, content_type: str, limit: int, out: BinaryIO | None = None) -> bytearray:
        """The request body, read into one buffer of its declared size, or copied to ``out`` chunk by chunk
        (then the buffer is empty): memory never grows with what a client only declares."""
        got = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
        if got != content_type:
            raise HttpError(HTTPStatus.UNSUPPORTED_MEDIA_TYPE,
                            f"expected Content-Type {content_type}, got {quote(got, 40) if got else 'none'}")
        length = content_length(self.headers, limit)
        reader: RequestReader = self.rfile  # type: ignore[assignment]
        reader.extend(length / 2**20 * BODY_SECONDS_PER_MIB)
        data, done = (bytearray(), reader.copy_to(out, length)) if out is not None else reader.read_into_buffer(length)
        self._body_read = True
        if done < length:
            raise HttpError(HTTPStatus.BAD_REQUEST, f"request body ended after {done} of {length} bytes")
        self._request_complete()
        return data

    # -- routing -----------------------------------------------------------------------------

    def do_GET(self) -> None:
        self._dispatch(self._get)

    do_HEAD = do_GET

    def do_POST(self) -> None:
        self._dispatch(self._post)

    def _get(self, path: str, query: dict[str, list[str]]) -> None:
        self._request_complete()
        service = self.server.service
        if path in ("/", "/index.html"):
            self._static("index.html")
        elif path.startswith("/static/"):
            self._static(path[len("/static/"):])
        elif path == "/api/info":
            info = service.info()
            info["limits"] = {**info["limits"], "upload_bytes": MAX_UPLOAD_BYTES, "open_frames": MAX_OPEN_FRAMES}
            self._json(info)
        elif path.startswith("/api/files/"):
            self._json(service.open_listed(numbered(path, "/api/files/", "", "file index",
                                                    f" (there are {len(service.files)} listed files)")))
        elif path.startswith("/api/body/"):
            body = service.body(numbered(path, "/api/body/", ".glb", "body number"))
            if body is None:
                raise HttpError(HTTPStatus.NOT_FOUND, f"no body {quote(path)}: only the last few motions keep one")
            self._send(HTTPStatus.OK, body, GLB_TYPE)
        elif path == "/favicon.ico":
            self._send(HTTPStatus.NO_CONTENT, b"", "text/plain")
        else:
            raise HttpError(HTTPStatus.NOT_FOUND, f"no such page {quote(path)}")

    def _post(self, path: str, query: dict[str, list[str]]) -> None:
        self._check_origin()
        service = self.server.service
        if path in POSTS:  # generate, edit, timeline
            request = parse_json(self._body("application/json", MAX_JSON_BYTES))
            self._log_api(f"{path[5:]} {request!r}"[:200])
            connection = self.connection
            self._json(POSTS[path](service, request, lambda: peer_closed(connection)))
        elif path == "/api/open":
            names = query.get("name") or [""]
            if len(names) > 1:
                raise HttpError(HTTPStatus.BAD_REQUEST, f"give one name=, got {len(names)}")
            name = service.upload_name(names[0])  # a bad name is refused before the body is read
            with tempfile.TemporaryDirectory(prefix="simdiff-serve-") as folder:
                file = Path(folder) / name
                with file.open("wb") as out:
                    self._body("application/octet-stream", MAX_UPLOAD_BYTES, out)
                self._log_api(f"open {name!r} ({file.stat().st_size} bytes)")
                self._json(service.open_upload_file(name, file))
        else:
            raise HttpError(HTTPStatus.NOT_FOUND, f"no such endpoint {quote(path)}")

    def _dispatch(self, route: Any) -> None:
        try:
            self._check_host()
            try:
                parts = urlsplit(self.path)
                query = parse_qs(parts.query, max_num_fields=MAX_QUERY_FIELDS)
            except ValueError as exc:
                raise HttpError(HTTPStatus.BAD_REQUEST, f"bad request target: {exc}") from None
            route(parts.path, query)
        except HttpError as exc:
            self._error(exc.status, str(exc))
        except QueueFull as exc:
            self._error(HTTPStatus.TOO_MANY_REQUESTS, str(exc), {"queue": exc.waiting, "limit": exc.limit})
        except (ModelUnavailable, UploadsBusy) as exc:
            self._error(HTTPStatus.SERVICE_UNAVAILABLE, str(exc))
        except GenerationCancelled as exc:
            self.close_connection = True
            self._log_api(str(exc))
        except NonFiniteResult as exc:
            self._error(HTTPStatus.UNPROCESSABLE_ENTITY, str(exc))
        except MotionTooLong as exc:
            self._error(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, str(exc))
        except SimdiffError as exc:
            self._error(HTTPStatus.BAD_REQUEST, str(exc))
        except TimeoutError:
            self._timed_out()
        except ConnectionError:
            self.close_connection = True
        except Exception as exc:  # noqa: BLE001 (a bug: keep serving, answer one line, log one line)
            self._internal_error(exc)

    # -- checks ------------------------------------------------------------------------------

    def _check_host(self) -> None:
        """Refuse requests addressed to another name (DNS rebinding) unless bound to all interfaces."""
        host = self.headers.get("Host")
        if host is None or self.server.any_host:
            return
        try:
            name = urlsplit(f"//{host}").hostname or ""
        except ValueError:
            raise HttpError(HTTPStatus.BAD_REQUEST, f"bad Host header {quote(host, 40)}") from None
        if name not in self.server.allowed_names:
            raise HttpError(HTTPStatus.FORBIDDEN, f"host {quote(host, 40)} is not this server")

    def _check_origin(self) -> None:
        """A browser's cross-site POST carries a foreign ``Origin``: refuse it."""
        origin = self.headers.get("Origin")
        host = self.headers.get("Host")
        if origin is None or host is None:
            return
        try:
            same = urlsplit(origin).netloc == host
        except ValueError:
            same = False
        if not same:
            raise HttpError(HTTPStatus.FORBIDDEN, f"cross-origin request from {quote(origin, 40)} refused")

    # -- answers -----------------------------------------------------------------------------

    def _static(self, name: str) -> None:
        data = self.server.static.get(name)
        if data is None:
            raise HttpError(HTTPStatus.NOT_FOUND, f"no such file {quote(name)}")
        self._send(HTTPStatus.OK, data, CONTENT_TYPES["." + name.rsplit(".", 1)[-1]])

    def _json(self, value: Any, status: HTTPStatus = HTTPStatus.OK) -> None:
        self._send(status, json.dumps(value, separators=(",", ":"), allow_nan=False).encode("utf-8"), "application/json")

    def send_error(self, code: int, message: str | None = None, explain: str | None = None) -> None:
        """The standard library's own errors (bad request line, 414, 431, 505) as one JSON line, not HTML."""
        try:
            status = HTTPStatus(code)
        except ValueError:
            status = HTTPStatus.BAD_REQUEST
        if self.request_version in ("", "HTTP/0.9"):
            self.request_version = "HTTP/1.0"  # an answer with a status line
        self._error(status, message or status.phrase)

    def _timed_out(self) -> None:
        self._error(HTTPStatus.REQUEST_TIMEOUT, f"no complete request within {self.server.request_timeout:g} s")

    def _internal_error(self, exc: BaseException) -> None:
        frames = traceback.extract_tb(exc.__traceback__)
        where = f" at {Path(frames[-1].filename).name}:{frames[-1].lineno}" if frames else ""
        print(f"[{self.log_date_time_string()}] internal error in {self.command} {quote(self.path)}: "
              f"{type(exc).__name__}: {one_line(str(exc), 200)}{where}", file=self.server.log, flush=True)
        self._error(HTTPStatus.INTERNAL_SERVER_ERROR,
                    f"internal error ({type(exc).__name__}); the server's log has a line about it")

    def _error(self, status: HTTPStatus, message: str, extra: dict[str, Any] | None = None) -> None:
        line = one_line(message) or status.phrase
        self._log_api(f"{int(status)} {line}")
        self.close_connection = True  # a body left unread must not be taken for the next request
        if self._answered:
            return  # part of an answer went out already: closing is all that is left
        headers = {"Connection": "close"}
        if status in (HTTPStatus.TOO_MANY_REQUESTS, HTTPStatus.SERVICE_UNAVAILABLE):
            headers["Retry-After"] = "5"
        if status == HTTPStatus.METHOD_NOT_ALLOWED:
            headers["Allow"] = ALLOWED_METHODS
        self._drop_unread_body()
        try:
            self._send(status, json.dumps({"error": line, **(extra or {})}).encode("utf-8"), "application/json", headers)
        except OSError:
            self._linger = False

    def _drop_unread_body(self) -> None:
        """Read and drop a small unread body so that the client gets the answer; a larger one is drained
        after the answer (:data:`LINGER_S`)."""
        reader: RequestReader = self.rfile  # type: ignore[assignment]
        if not self._head_read or self._body_read or reader.expired():
            return  # nothing to drop, or a client too slow to wait for
        self._body_read = True
        length = (self.headers.get("Content-Length") or "0").strip()
        if self.headers.get("Transfer-Encoding") is not None or not length.isdecimal() or int(length) > DRAIN_BYTES:
            self._linger = True
        elif int(length):
            try:
                reader.read(int(length))
            except OSError:
                pass

    def _send(self, status: HTTPStatus, data: bytes, content_type: str, headers: dict[str, str] | None = None) -> None:
        self._request_complete()
        self._answered = True
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

    def finish(self) -> None:
        try:
            super().finish()
        finally:
            if self._linger:
                linger(self.connection, LINGER_S)

    def _log_api(self, text: str) -> None:
        if self.server.verbose:
            print(f"[{self.log_date_time_string()}] {self.command} {text}", file=self.server.log, flush=True)

    def log_message(self, format: str, *args: Any) -> None:
        """Silence the per-request access log; API calls are logged by ``_log_api``."""


class ViewerServer(ThreadingHTTPServer):
    """The viewer's server; serve with ``serve_forever()`` or :meth:`start_in_thread`.

    Args:
        service: the API's back end.
        host: address to bind (default loopback only).
        port: TCP port; 0 picks a free one (see :attr:`url`).
        verbose: log API calls and errors to ``log``.
        log: where logs go (default stderr).
        request_timeout: seconds for a whole request to arrive (default :data:`REQUEST_DEADLINE_S`).
        max_connections: connections served at once (default :data:`MAX_CONNECTIONS`; see :data:`EVICT_GRACE_S`).
    Raises:
        SimdiffError: the address cannot be bound (port in use, unknown host).
    """

    daemon_threads = True
    request_queue_size = 128

    def __init__(self, service: MotionService, host: str = "127.0.0.1", port: int = 8765, *,
                 verbose: bool = False, log: TextIO | None = None, request_timeout: float | None = None,
                 max_connections: int | None = None) -> None:
        request_timeout = REQUEST_DEADLINE_S if request_timeout is None else request_timeout
        max_connections = MAX_CONNECTIONS if max_connections is None else max_connections
        if not request_timeout > 0 or max_connections < 1:
            raise SimdiffError(f"request_timeout must be > 0 and max_connections ≥ 1, got {request_timeout}, {max_connections}")
        self.request_timeout = float(request_timeout)
        self.write_timeout = WRITE_TIMEOUT_S
        self.slots = Slots(max_connections, EVICT_GRACE_S, EVICTED_ANSWER)
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
        self.static = static_files()
        self.any_host = host in ("", "0.0.0.0", "::")
        self.allowed_names = LOOPBACK_NAMES | {host, socket.gethostname()}

    def process_request(self, request: Any, client_address: Any) -> None:
        """Serve the connection in a thread if it gets a slot (:class:`Slots`), else answer 503 and close it."""
        if not self.slots.admit(request):
            try:
                request.setblocking(False)
                request.send(BUSY_ANSWER)  # never blocks the accepting thread
            except OSError:
                pass
            self.shutdown_request(request)
            return
        super().process_request(request, client_address)  # a failure here: shutdown_request frees the slot

    def shutdown_request(self, request: Any) -> None:
        """Free the connection's slot, then close it (in that order: see :meth:`Slots.admit`)."""
        self.slots.release(request)
        super().shutdown_request(request)

    def handle_error(self, request: Any, client_address: Any) -> None:
        """An exception outside a request's handling: one log line, no traceback (a gone client: nothing)."""
        exc = sys.exc_info()[1]
        if exc is None or isinstance(exc, (ConnectionError, TimeoutError)):
            return
        print(f"simdiff serve: error on a connection from {client_address[0]}: {type(exc).__name__}: "
              f"{one_line(str(exc), 200)}", file=self.log, flush=True)

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
