"""Wire format of the viewer's API: strict JSON request bodies, one-line error messages, the canned answers the
server sends without a handler."""

from __future__ import annotations

import json
import math
import re
import threading
from collections import OrderedDict
from http import HTTPStatus
from importlib import resources
from typing import Any

import numpy as np

CONTENT_TYPES: dict[str, str] = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".mjs": "text/javascript; charset=utf-8",
    ".css": "text/css; charset=utf-8",
}
GLB_TYPE: str = "model/gltf-binary"
_STATIC_NAME = re.compile(r"[a-z0-9_-]+\.(html|js|css)")
_VENDOR_NAME = re.compile(r"vendor(/[A-Za-z0-9_][A-Za-z0-9_.-]*)+\.(js|mjs)")


def static_files() -> dict[str, bytes]:
    """The page's files, read once from the package: relative name (``ui.js``, ``vendor/three/build/...js``) →
    bytes. Only these names are served, so no request path can reach another file."""
    files: dict[str, bytes] = {}
    folders = [("", resources.files("simdiff.serve") / "static")]
    while folders:
        prefix, folder = folders.pop()
        for entry in folder.iterdir():
            name = prefix + entry.name
            if entry.is_dir() and (name == "vendor" or name.startswith("vendor/")):
                folders.append((name + "/", entry))
            elif entry.is_file() and (_STATIC_NAME.fullmatch(name) or _VENDOR_NAME.fullmatch(name)):
                files[name] = entry.read_bytes()
    return files


def numbered(path: str, prefix: str, suffix: str, what: str, hint: str = "") -> int:
    """The whole number in ``path`` between ``prefix`` and ``suffix``.

    Raises:
        HttpError: 400 naming ``what`` (and ``hint``) when it is not 1 to 9 digits.
    """
    text = path[len(prefix):]
    if not (text.endswith(suffix) and re.fullmatch(r"[0-9]{1,9}", text[:len(text) - len(suffix)])):
        raise HttpError(HTTPStatus.BAD_REQUEST, f"{what} must be a whole number{hint}, got {quote(text, 40)}")
    return int(text[:len(text) - len(suffix)])


class BodyCache:
    """The joints of the last ``size`` motions sent to the page, by number, and their skinned bodies as ``.glb``
    bytes: built on first request by :func:`~simdiff.motion.rigid.fit` on the motion's own skeleton from the
    joints exactly as sent (so that body and stick figure agree), then kept. The joints stay too: a request may
    name the motion as its source (:meth:`joints`), which also keeps it among the last ``size``. Memory is
    bounded by ``size`` motions; one body is built at a time."""

    def __init__(self, size: int) -> None:
        self.size = size
        self._items: OrderedDict[int, list[Any]] = OrderedDict()  # number → [joints, glb bytes or None]
        self._count = 0
        self._lock = threading.Lock()
        self._build = threading.Lock()

    def add(self, joints: np.ndarray) -> int:
        """Keep (T, 22, 3) ``joints``; returns their number (older motions beyond ``size`` are dropped)."""
        with self._lock:
            self._count += 1
            self._items[self._count] = [joints, None]
            while len(self._items) > self.size:
                self._items.popitem(last=False)
            return self._count

    def joints(self, number: int) -> np.ndarray | None:
        """The (T, 22, 3) joints of motion ``number`` as sent (None when unknown or no longer kept); it becomes the
        most recently used, the last to be dropped."""
        with self._lock:
            item = self._items.get(number)
            if item is None:
                return None
            self._items.move_to_end(number)
            return item[0]

    def glb(self, number: int) -> bytes | None:
        """The body of motion ``number``; None when it is unknown or no longer kept."""
        from simdiff.motion.io.gltf_writer import glb_bytes
        from simdiff.motion.rigid import fit
        from simdiff.motion.skeleton import FPS

        with self._build:
            with self._lock:
                item = self._items.get(number)
            if item is None:
                return None
            if item[1] is None:
                item[1] = glb_bytes(fit(item[0], None), FPS)
            return item[1]


class HttpError(Exception):
    """An answer other than 200, with a one-line message for the page."""

    def __init__(self, status: HTTPStatus, message: str) -> None:
        super().__init__(message)
        self.status = status


_EVICTED = b'{"error": "the request did not arrive in time: closed to make room for another connection"}'
EVICTED_ANSWER = (b"HTTP/1.0 408 Request Timeout\r\nContent-Type: application/json\r\nConnection: close\r\n"
                   b"Content-Length: " + str(len(_EVICTED)).encode() + b"\r\n\r\n" + _EVICTED)
_BUSY = b'{"error": "the server is busy: too many connections; try again in a moment"}'
BUSY_ANSWER = (b"HTTP/1.0 503 Service Unavailable\r\nContent-Type: application/json\r\nRetry-After: 5\r\n"
                b"Connection: close\r\nContent-Length: " + str(len(_BUSY)).encode() + b"\r\n\r\n" + _BUSY)


def content_length(headers: Any, limit: int) -> int:
    """The declared body size from request ``headers`` (an ``email.message.Message``).

    Raises:
        HttpError: 411 a transfer encoding (chunked) or no ``Content-Length``; 400 a bad or repeated one with
            different values; 413 over ``limit`` (the body is not read).
    """
    if headers.get("Transfer-Encoding") is not None:
        raise HttpError(HTTPStatus.LENGTH_REQUIRED, "transfer encodings (chunked) are not accepted: "
                                                    "send the body with a Content-Length")
    values = [v.strip() for v in headers.get_all("Content-Length") or []]
    if not values:
        raise HttpError(HTTPStatus.LENGTH_REQUIRED, "Content-Length is required")
    if len(set(values)) != 1 or not re.fullmatch(r"[0-9]{1,30}", values[0]):
        raise HttpError(HTTPStatus.BAD_REQUEST,
                        f"Content-Length must be one whole number of bytes, got {quote(', '.join(values), 40)}")
    length = int(values[0])
    if length > limit:
        raise HttpError(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"request body of {length} bytes is over the "
                                                             f"{limit}-byte limit")
    return length


def quote(text: str, limit: int = 60) -> str:
    """``repr(text)`` cut to about ``limit`` characters."""
    shown = repr(text)
    return shown if len(shown) <= limit else shown[:limit - 4] + "...'"


def one_line(text: str, limit: int = 300) -> str:
    line = " ".join(text.split())
    return line if len(line) <= limit else line[:limit - 3] + "..."


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number JSON allows")


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"number {text[:24]} is out of range")
    return value


def _bounded_int(text: str) -> int:
    if len(text) > 40:
        raise ValueError(f"integer of {len(text)} digits is out of range")
    return int(text)


def parse_json(body: bytes | bytearray) -> Any:
    """A JSON body; ``NaN``, ``Infinity``, overflowing numbers, bad UTF-8 or deep nesting: 400."""
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise HttpError(HTTPStatus.BAD_REQUEST, f"request body is not valid UTF-8 (byte {exc.start})") from None
    try:
        return json.loads(text, parse_constant=_no_constant, parse_float=_finite_float, parse_int=_bounded_int)
    except RecursionError:
        raise HttpError(HTTPStatus.BAD_REQUEST, "request body is not valid JSON: nested too deeply") from None
    except ValueError as exc:  # json.JSONDecodeError included
        raise HttpError(HTTPStatus.BAD_REQUEST, f"request body is not valid JSON: {exc}") from None
