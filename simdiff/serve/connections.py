"""Connection plumbing of the viewer's server: a whole-request read deadline, connection slots that slow
senders cannot keep, and noticing a client that went away.

:class:`DeadlineReader` is the raw reader under a handler's ``rfile``: every ``recv`` waits at most the
time left until the request's deadline, so trickling one byte at a time does not extend it, and the request
line plus headers have a byte budget. :class:`Slots` counts the connections being served; when all are taken,
the one that has been sending its request the longest (past a grace period) is closed to make room, so slow
senders cannot lock others out. :func:`peer_closed` tells whether the client closed its end, without
consuming what it sent.
"""

from __future__ import annotations

import io
import socket
import threading
import time
from dataclasses import dataclass, field
from typing import BinaryIO


class HeadTooLarge(Exception):
    """The request line and headers are over their byte budget (answered 431)."""


class DeadlineReader(io.RawIOBase):
    """Raw socket reads bounded by one deadline for the whole request.

    Args:
        sock: the connection.
    Attributes:
        deadline: ``time.monotonic()`` value after which reads raise :class:`TimeoutError`.
    """

    def __init__(self, sock: socket.socket) -> None:
        super().__init__()
        self._sock = sock
        self.deadline = float("inf")

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: bytearray | memoryview) -> int:  # type: ignore[override]
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError("the request deadline passed")
        self._sock.settimeout(left)
        return self._sock.recv_into(buffer)


class RequestReader:
    """A handler's ``rfile``: buffered :class:`DeadlineReader` reads; ``readline`` spends the head budget
    (request line and headers) until :meth:`end_head`.

    Args:
        sock: the connection.
    """

    def __init__(self, sock: socket.socket) -> None:
        self.raw = DeadlineReader(sock)
        self._buffer = io.BufferedReader(self.raw, 64 * 1024)
        self._head_left = 0
        self._in_head = False

    def start(self, deadline_s: float, head_bytes: int) -> None:
        """A new request: ``deadline_s`` seconds from now for all of it, ``head_bytes`` for its head."""
        self.raw.deadline = time.monotonic() + deadline_s
        self._head_left = head_bytes
        self._in_head = True

    def expired(self) -> bool:
        """True once the request's deadline has passed."""
        return time.monotonic() >= self.raw.deadline

    def extend(self, seconds: float) -> None:
        """Move the deadline ``seconds`` later (time for a large body)."""
        self.raw.deadline += seconds

    def read_into_buffer(self, length: int) -> tuple[bytearray, int]:
        """Read up to ``length`` bytes into one new buffer of that size: (buffer, bytes read: less at EOF)."""
        data = bytearray(length)
        done = 0
        with memoryview(data) as view:
            while done < length:
                count = self._buffer.readinto(view[done:])
                if not count:
                    break
                done += count
        return data, done

    def copy_to(self, out: BinaryIO, length: int) -> int:
        """Copy up to ``length`` bytes to ``out`` in 64 KiB chunks; returns the bytes copied (less at EOF)."""
        chunk = bytearray(64 * 1024)
        done = 0
        with memoryview(chunk) as view:
            while done < length:
                count = self._buffer.readinto(view[:min(len(chunk), length - done)])
                if not count:
                    break
                out.write(view[:count])
                done += count
        return done

    def end_head(self) -> None:
        """The headers are read: ``readline`` no longer counts (the deadline still holds)."""
        self._in_head = False

    def readline(self, limit: int = -1) -> bytes:
        if not self._in_head:
            return self._buffer.readline(limit)
        if self._head_left <= 0:
            raise HeadTooLarge
        cap = self._head_left if limit is None or limit < 0 else min(limit, self._head_left)
        line = self._buffer.readline(cap)
        self._head_left -= len(line)
        if self._head_left <= 0 and not line.endswith(b"\n"):
            raise HeadTooLarge
        return line

    def read(self, size: int = -1) -> bytes:
        return self._buffer.read(size)

    def readinto(self, buffer: bytearray | memoryview) -> int:
        return self._buffer.readinto(buffer)

    def close(self) -> None:
        self._buffer.close()

    @property
    def closed(self) -> bool:
        return self._buffer.closed


def peer_closed(sock: socket.socket) -> bool:
    """True when the client closed or reset its end of ``sock`` (peeks: consumes nothing).

    Bytes waiting to be read count as a live client. Call from the thread that owns the socket.
    """
    timeout = sock.gettimeout()
    try:
        sock.settimeout(0.0)
        return sock.recv(1, socket.MSG_PEEK) == b""
    except (BlockingIOError, InterruptedError):
        return False
    except OSError:
        return True
    finally:
        try:
            sock.settimeout(timeout)
        except OSError:
            pass


def linger(sock: socket.socket, seconds: float) -> None:
    """After an answer to a request whose body was left unread: stop sending, then drop what the client still
    sends, for at most ``seconds``, so that a client that sends its whole body before reading sees the answer
    rather than a reset connection. Nothing is kept: memory stays at one 64 KiB chunk."""
    try:
        sock.shutdown(socket.SHUT_WR)
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            sock.settimeout(left)
            if not sock.recv(64 * 1024):
                return
    except OSError:
        pass


@dataclass
class _Slot:
    sock: socket.socket
    since: float = field(default_factory=time.monotonic)
    reading: bool = True


class Slots:
    """The connections being served: at most ``limit``; a full table makes room by closing the connection
    that has been sending its request the longest, once it has been at it for ``grace_s`` seconds.

    Args:
        limit: connections served at once.
        grace_s: how long a connection may send its request before a newcomer may take its slot.
        evicted_answer: bytes sent (best effort, without blocking) to a connection closed for a newcomer.
    """

    def __init__(self, limit: int, grace_s: float, evicted_answer: bytes = b"") -> None:
        self.limit = limit
        self.grace_s = grace_s
        self._answer = evicted_answer
        self._lock = threading.Lock()
        self._held: dict[socket.socket, _Slot] = {}
        self.evictions = 0

    def admit(self, sock: socket.socket) -> bool:
        """Take a slot for ``sock``; False when every slot is serving a request already read (answer 503)."""
        with self._lock:
            if len(self._held) >= self.limit:
                now = time.monotonic()
                readers = [s for s in self._held.values() if s.reading and now - s.since >= self.grace_s]
                if not readers:
                    return False
                victim = min(readers, key=lambda s: s.since)
                del self._held[victim.sock]
                self.evictions += 1
                # under the lock: its thread closes the socket only after release(), so the fd is still its own
                _close_for_newcomer(victim.sock, self._answer)
            self._held[sock] = _Slot(sock)
        return True

    def done_reading(self, sock: socket.socket) -> bool:
        """``sock``'s request is read: its slot can no longer be taken. False when it was taken already."""
        with self._lock:
            slot = self._held.get(sock)
            if slot is None:
                return False
            slot.reading = False
            return True

    def release(self, sock: socket.socket) -> None:
        """``sock`` is finished, call before closing it (a no-op when its slot went to a newcomer)."""
        with self._lock:
            self._held.pop(sock, None)

    def count(self) -> dict[str, int]:
        """``{held, reading, limit, evictions}``."""
        with self._lock:
            reading = sum(s.reading for s in self._held.values())
            return {"held": len(self._held), "reading": reading, "limit": self.limit, "evictions": self.evictions}


def _close_for_newcomer(sock: socket.socket, answer: bytes) -> None:
    """Send ``answer`` if the socket takes it at once, then shut the connection (its thread wakes and ends)."""
    try:
        if answer:
            sock.send(answer, getattr(socket, "MSG_DONTWAIT", 0))
    except OSError:
        pass
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass
