"""The study server's connections: what uvicorn does not bound by itself.

uvicorn waits for a request head as long as a client likes and takes every connection the
kernel hands it, so one address with a thousand idle sockets can use up the process's file
descriptors: then nothing is accepted, no file opens, and every failure is logged with a
traceback. Here, around uvicorn's own HTTP/1.1 protocol:

* **header timeout**: a connection must deliver a whole request head within ``header_timeout``
  s of being opened or of its last answer, else it is closed (with a 408 when it had sent part
  of one). The body has its own timeout in :class:`activeintent.web.limits.BodyGuard`;
* **connections per client address** (``max_connections_per_client``) and **in all**: the
  latter never more than the file-descriptor limit minus a reserve for the sessions' files,
  videos and pipes. A connection over either gets a short 503 and is closed at once;
* **no log flood**: refusals, accept failures for lack of descriptors, errors of the HTTP
  layer and uvicorn's own warnings are logged at most once per ten seconds each, as one line
  (the next one says how many were left out).

:func:`serve` runs an app of :func:`activeintent.web.server.create_app` this way;
:func:`server_config` is the same configuration for a :class:`StudyServer` of one's own.
"""

from __future__ import annotations

import asyncio
import errno
import json
import logging
import re
import resource
import time
from collections import Counter
from typing import Any

import uvicorn
from starlette.types import ASGIApp, Receive, Scope, Send
from uvicorn.protocols.http.h11_impl import H11Protocol

from activeintent.web.errors import RateLimitedLog, RepeatGate, error_body

log = logging.getLogger("activeintent.web")

MAX_HEAD_BYTES = 16 * 1024  # a request line and headers; the pages send well under 2 KiB
_HEAD_END = re.compile(rb"\r?\n\r?\n")  # h11 also takes bare newlines
KEEP_ALIVE_S = 5  # an idle connection after an answer is closed after this long
OUT_OF_FDS = (errno.EMFILE, errno.ENFILE)


def fd_reserve(soft: int) -> int:
    """Descriptors kept free of connections: the sessions' files, videos, pipes and threads."""
    return max(64, soft // 4)


def connection_budget(max_connections: int) -> tuple[int, int | None]:
    """(connections allowed at once, the soft RLIMIT_NOFILE it was derived from or None)."""
    soft, _ = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return max_connections, None
    return max(8, min(max_connections, soft - fd_reserve(soft))), soft


def canned(status: int, code: str, message: str, retry_after: int | None = None) -> bytes:
    """A whole HTTP/1.1 answer in the API's error shape, for a connection the app never sees."""
    body = json.dumps(error_body(status, code, message)).encode()
    phrase = {408: "Request Timeout", 431: "Request Header Fields Too Large", 503: "Service Unavailable"}[status]
    head = [f"HTTP/1.1 {status} {phrase}", "Content-Type: application/json",
            f"Content-Length: {len(body)}", "Connection: close"]
    if retry_after is not None:
        head.append(f"Retry-After: {retry_after}")
    return ("\r\n".join(head) + "\r\n\r\n").encode() + body


class ConnectionGuard:
    """The open connections of one server, by client address; all on the event loop's thread."""

    def __init__(self, header_timeout: float = 10.0, max_connections_per_client: int = 32,
                 max_connections: int = 1000):
        self.header_timeout = header_timeout
        self.per_client = max_connections_per_client
        self.max_connections, self.nofile = connection_budget(max_connections)
        # what one accept burst may take before the refusals close again (asyncio accepts up to
        # the backlog at once): small enough to stay inside the descriptor reserve
        reserve = fd_reserve(self.nofile) if self.nofile else 256
        self.backlog = max(16, min(2048, reserve // 4))
        self.open: dict[tuple[str, int], GuardedConnection] = {}
        self.per_host: Counter[str] = Counter()
        self.log = RateLimitedLog(log)
        where = f" (the file-descriptor limit is {self.nofile})" if self.nofile else ""
        self.busy = canned(503, "server_busy", f"the server has {self.max_connections} connections open, as "
                           f"many as it takes{where}; try again in a few seconds", retry_after=5)
        self.too_many = canned(503, "too_many_connections", f"this address has {self.per_client} connections "
                               "open, as many as one client may; close some or try again", retry_after=5)
        self.timeout = canned(408, "request_timeout",
                              f"no complete request head within {header_timeout:g} s; the connection is closed")
        self.head_too_large = canned(431, "head_too_large", f"the request head is larger than {MAX_HEAD_BYTES} "
                                     "bytes (request line and headers); the connection is closed")

    # -- connections ---------------------------------------------------------------------------
    def protocol(self, **uvicorn_kwargs: Any) -> GuardedConnection:
        """uvicorn's protocol factory: its HTTP/1.1 protocol, wrapped."""
        return GuardedConnection(self, H11Protocol(**uvicorn_kwargs))

    def admit(self, conn: GuardedConnection) -> bytes | None:
        """None when ``conn`` may stay, else the answer that refuses it."""
        host = conn.peer[0]
        if len(self.open) >= self.max_connections:
            self.log.warning("full", "%d connections open (the most this server takes%s): refusing new ones",
                             len(self.open), f"; file-descriptor limit {self.nofile}" if self.nofile else "")
            return self.busy
        if self.per_host[host] >= self.per_client:
            self.log.warning("client", "%s has %d connections open (limit %d per client): refusing more",
                             host, self.per_host[host], self.per_client)
            return self.too_many
        self.open[conn.peer] = conn
        self.per_host[host] += 1
        return None

    def release(self, conn: GuardedConnection) -> None:
        if self.open.get(conn.peer) is conn:
            del self.open[conn.peer]
            self.per_host[conn.peer[0]] -= 1
            if self.per_host[conn.peer[0]] <= 0:
                del self.per_host[conn.peer[0]]

    def connection(self, client: Any) -> GuardedConnection | None:
        """The connection an ASGI scope's ``client`` (host, port) came on, if it is one of ours."""
        if not client:
            return None
        return self.open.get((str(client[0]), int(client[1])))

    # -- the event loop ------------------------------------------------------------------------
    def loop_error(self, loop: asyncio.AbstractEventLoop, context: dict) -> None:
        """The loop's exception handler: running out of descriptors at accept is one short line
        now and then (asyncio retries the accept a second later), not a traceback each time."""
        exc = context.get("exception")
        if isinstance(exc, OSError) and exc.errno in OUT_OF_FDS:
            self.log.warning("fds", "out of file descriptors (%s): new connections wait", exc.strerror)
            return
        loop.default_exception_handler(context)


class GuardedConnection(asyncio.Protocol):
    """One connection: uvicorn's protocol inside, admission and the header timeout around it."""

    def __init__(self, guard: ConnectionGuard, inner: asyncio.Protocol):
        self.guard, self.inner = guard, inner
        self.transport: asyncio.Transport | None = None
        self.peer: tuple[str, int] = ("?", id(self))
        self.admitted = False
        self.requests = 0  # in progress on this connection (pipelined ones may overlap briefly)
        self._timer: asyncio.Handle | None = None
        self._partial = False  # bytes arrived since the wait for a request head began
        self._head_bytes = 0  # of the request head being waited for, however it arrives
        self._in_head = True  # waiting for a head's end (else: a request's body, or nothing)
        self._tail = b""  # the last bytes seen, for an end of head split across reads
        self._refused = False  # its head was too large: answered 431 and closing

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport  # type: ignore[assignment]
        peer = transport.get_extra_info("peername")
        if isinstance(peer, tuple) and len(peer) >= 2:
            self.peer = (str(peer[0]), int(peer[1]))
        refusal = self.guard.admit(self)
        if refusal is not None:
            # nothing of it was read: closing now frees the descriptor at once
            transport.write(refusal)  # type: ignore[attr-defined]
            transport.close()
            return
        self.admitted = True
        self.inner.connection_made(transport)
        self._wait_for_head()

    def data_received(self, data: bytes) -> None:
        if not self.admitted or self._refused:
            return
        if self._timer is not None:
            self._partial = True
        if self._in_head and self._head_too_large(data):
            self._refused = True  # nothing more of it reaches the HTTP layer
            self._cancel()
            self.transport.write(self.guard.head_too_large)
            self.transport.close()
            return
        try:
            self.inner.data_received(data)
        except Exception as err:  # the HTTP layer could not answer this itself: end the connection
            self.guard.log.warning("protocol", "closed a connection from %s after an HTTP error: %s",
                                   self.peer[0], err)
            self.transport.abort()

    def eof_received(self) -> bool | None:
        return self.inner.eof_received() if self.admitted else None

    def connection_lost(self, exc: Exception | None) -> None:
        self._cancel()
        self.guard.release(self)
        if self.admitted:
            self.inner.connection_lost(exc)

    def pause_writing(self) -> None:
        if self.admitted:
            self.inner.pause_writing()

    def resume_writing(self) -> None:
        if self.admitted:
            self.inner.resume_writing()

    # -- request phases (told by RequestPhases, on the loop) ------------------------------------
    def request_started(self) -> None:
        self.requests += 1
        self._cancel()

    def request_finished(self) -> None:
        self.requests = max(0, self.requests - 1)
        if self.requests == 0 and not self.transport.is_closing():
            self._wait_for_head()

    def _head_too_large(self, data: bytes) -> bool:
        """Count the bytes of the head being waited for, up to its end (an empty line): h11's
        own limit binds only a head that is still incomplete after a read, so a head of any size
        sent in one piece went through."""
        window = self._tail + data
        end = _HEAD_END.search(window)
        if end is None:
            self._head_bytes += len(data)
            self._tail = window[-3:]
            return self._head_bytes > MAX_HEAD_BYTES
        self._head_bytes += end.end() - len(self._tail)
        self._in_head = False
        return self._head_bytes > MAX_HEAD_BYTES

    # -- the header timeout ---------------------------------------------------------------------
    def _wait_for_head(self) -> None:
        self._cancel()
        self._partial = False
        self._head_bytes, self._in_head, self._tail = 0, True, b""
        self._timer = asyncio.get_running_loop().call_later(self.guard.header_timeout, self._expired)

    def _cancel(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _expired(self) -> None:
        # a head that has just arrived starts its request on the next turn of the loop: let it
        self._timer = asyncio.get_running_loop().call_soon(self._close_idle)

    def _close_idle(self) -> None:
        self._timer = None
        if self.requests or self.transport.is_closing():
            return
        if self._partial:
            self.transport.write(self.guard.timeout)
        self.transport.close()


class RequestPhases:
    """ASGI middleware, outermost: tells a request's connection when the request starts (its
    head is complete: no header timeout) and when its answer is done (the timeout starts
    again for the next one)."""

    def __init__(self, app: ASGIApp, guard: ConnectionGuard):
        self.app, self.guard = app, guard

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        conn = self.guard.connection(scope.get("client")) if scope["type"] == "http" else None
        if conn is not None:
            conn.request_started()
        try:
            await self.app(scope, receive, send)
        finally:
            if conn is not None:
                conn.request_finished()


class QuietRepeats(logging.Filter):
    """A logger's same message at most once per ``every`` s (uvicorn warns once per malformed
    request: a flood of them would be a flood of lines); the next one says how many were left out."""

    def __init__(self, every: float = 10.0, clock=time.monotonic):
        super().__init__()
        self.gate = RepeatGate(every, clock)  # by a message's first 200 characters (messages are templates)

    def filter(self, record: logging.LogRecord) -> bool:
        note = self.gate.admit(str(record.msg)[:200])
        if note is None:
            return False
        if note:
            record.msg = f"{record.msg}{note}"
        return True


class StudyServer(uvicorn.Server):
    """uvicorn's server with the connection guard's handler for the loop's errors and repeated
    log lines of the HTTP layer kept down."""

    def __init__(self, config: uvicorn.Config, guard: ConnectionGuard):
        super().__init__(config)
        self.guard = guard

    async def startup(self, sockets=None) -> None:
        asyncio.get_running_loop().set_exception_handler(self.guard.loop_error)
        for name in ("uvicorn.error", "asyncio"):
            logger = logging.getLogger(name)
            if not any(isinstance(f, QuietRepeats) for f in logger.filters):
                logger.addFilter(QuietRepeats())
        await super().startup(sockets=sockets)


def server_config(app: Any, host: str, port: int, log_level: str = "warning") -> uvicorn.Config:
    """uvicorn's configuration for the study app (``app.state.connections``: its guard)."""
    guard: ConnectionGuard = app.state.connections
    return uvicorn.Config(
        app, host=host, port=port, log_level=log_level,
        http=guard.protocol,  # uvicorn's h11 protocol inside the guard
        ws="none",  # the study has no WebSockets: no upgrade to another protocol
        lifespan="on",
        proxy_headers=False,  # a client is its TCP peer: X-Forwarded-For is not trusted
        server_header=False,
        backlog=guard.backlog,
        timeout_keep_alive=KEEP_ALIVE_S,
        h11_max_incomplete_event_size=MAX_HEAD_BYTES,
    )


def serve(app: Any, host: str, port: int, log_level: str = "warning") -> None:
    """Run the study app until interrupted (what `activeintent serve` does)."""
    try:
        StudyServer(server_config(app, host, port, log_level), app.state.connections).run()
    except KeyboardInterrupt:  # uvicorn raises Ctrl-C again once it has shut down: a normal end
        pass
