"""What keeps one client from spoiling a study for the others.

* :class:`BodyGuard` (ASGI middleware): refuses a request with both Content-Length and
  Transfer-Encoding (400, ambiguous framing), refuses a body larger than ``max_body_bytes`` before
  reading it (by its Content-Length) or as soon as a streamed body passes the limit (413; the
  rest is drained, bounded, so that the client reads the 413 instead of a reset), gives a body
  ``body_timeout`` s to arrive (408), and lets only strict JSON into the API: UTF-8, finite numbers, integers within ±2**53, no lone
  surrogates, no duplicate keys, nesting at most 32 deep (422; 415 for a non-JSON type).
* :class:`SessionLimits`: admission of new sessions (at most ``max_sessions_per_client`` in
  progress per client address, ``max_new_sessions_per_hour`` started per client address per
  hour, the study's ``max_sessions`` in all), the idle timeout that cancels a session nobody
  has asked about for ``idle_timeout`` seconds (so an abandoned tab frees its slot), and the
  quota on what clients may write into a session's ``events.jsonl``.

Time comes from an injectable clock so that expiry can be tested without waiting. What is
bounded below the app (request heads, connections per address and in all) is in
:mod:`activeintent.web.transport`.
"""

from __future__ import annotations

import asyncio
import json
import math
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, field_validator
from starlette.datastructures import Headers
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from activeintent.web.errors import ApiError, error_response
from activeintent.web.session import SessionManager, WebSession

MAX_JSON_DEPTH = 32
MAX_JSON_INT = 2**53  # what a browser's Number holds exactly
# bytes an events.jsonl line adds around the event itself ("server_ts", "source")
EVENT_LINE_OVERHEAD = 64


class Limits(BaseModel):
    """The server's limits (the study's ``max_sessions`` is the global session limit)."""

    model_config = ConfigDict(extra="forbid")

    max_sessions_per_client: int = Field(2, ge=1, description="sessions in progress per client address")
    max_new_sessions_per_hour: int = Field(30, ge=1, description="sessions one client address may start per hour")
    idle_timeout: float = Field(
        180.0, gt=0, description="seconds without a request about a session before it is cancelled"
    )
    max_body_bytes: int = Field(128 * 1024, ge=1024, description="largest request body")
    drain_bytes: int = Field(
        16 * 1024 * 1024, ge=0, description="most of a refused body read (and dropped) so that its "
        "sender can read the refusal; a larger body's sender may see the connection reset instead")
    body_timeout: float = Field(
        30.0, gt=0, description="seconds for a request body to arrive (and for draining a refused one)")
    header_timeout: float = Field(
        10.0, gt=0, description="seconds for a request head to arrive on a new or idle connection")
    max_connections_per_client: int = Field(32, ge=1, description="connections open at once from one address")
    max_connections: int = Field(
        1000, ge=8, description="connections open at once in all (never more than the file-descriptor "
        "limit leaves after a reserve for the sessions)")
    events_quota_bytes: int = Field(
        5 * 1024 * 1024, ge=1024, description="largest events.jsonl clients may fill in one session"
    )
    settle_seconds: float = Field(
        2.0, ge=0, description="how long a new session waits for idle sessions it cancelled to end"
    )
    reconnect_grace: float = Field(
        20.0, gt=0, description="seconds a session whose page said it was closing (a beacon on unload) "
        "waits for a request from a page of it (a reload, the next page) before it is cancelled")
    shared_clients: list[str] = Field(
        default_factory=list, description="addresses or networks (CIDR) that several participants share (a lab "
        "behind one address, a proxy): no per-client session limits for them, only --max-sessions")

    @field_validator("shared_clients")
    @classmethod
    def _networks(cls, nets: list[str]) -> list[str]:
        import ipaddress

        for net in nets:
            try:
                ipaddress.ip_network(net, strict=False)
            except ValueError:
                raise ValueError(f"{net!r} is not an address or network (e.g. 10.0.0.5 or 10.0.0.0/24)") from None
        return nets

    def shared(self, client: str) -> bool:
        """Whether ``client`` is one of the shared addresses."""
        import ipaddress

        try:
            address = ipaddress.ip_address(client)
        except ValueError:
            return False
        for net in self.shared_clients:
            try:
                if address in ipaddress.ip_network(net, strict=False):
                    return True
            except ValueError:
                continue
        return False


# -- strict JSON --------------------------------------------------------------------------------
class _Rejected:
    """Stands in for a value JSON must not carry, so the walk can say where it was."""

    def __init__(self, why: str):
        self.why = why


class StrictJSONError(ValueError):
    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code, self.message = code, message


def _float(text: str) -> float | _Rejected:
    value = float(text)
    return value if math.isfinite(value) else _Rejected(f"{text[:20]} is not a finite number")


def _int(text: str) -> int | _Rejected:
    digits = text.lstrip("-")
    if len(digits) > 16 or abs(int(text)) > MAX_JSON_INT:
        return _Rejected(f"{text[:20]}{'…' if len(text) > 20 else ''} is out of range (at most ±2**53)")
    return int(text)


def _constant(name: str) -> _Rejected:
    return _Rejected(f"{name} is not a finite number (JSON allows only finite numbers)")


def _object(pairs: list[tuple[str, Any]]) -> dict:
    obj: dict = {}
    for key, value in pairs:
        if key in obj:
            raise StrictJSONError("invalid_json", f"the key {key[:40]!r} appears twice in one object")
        obj[key] = value
    return obj


def _utf8(text: str) -> bool:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def parse_strict_json(raw: bytes) -> Any:
    """The value of a JSON body, or :class:`StrictJSONError` saying what is wrong and where."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise StrictJSONError("invalid_json", "the body is not UTF-8 text") from None
    try:
        value = json.loads(text, parse_float=_float, parse_int=_int, parse_constant=_constant,
                           object_pairs_hook=_object)
    except json.JSONDecodeError as err:
        raise StrictJSONError("invalid_json", f"the body is not valid JSON: {err.msg} at character {err.pos}") from None
    except RecursionError:
        raise StrictJSONError("invalid_json", f"the body nests deeper than {MAX_JSON_DEPTH} levels") from None
    # walk without recursion: (value, path, depth)
    stack: list[tuple[Any, str, int]] = [(value, "", 0)]
    while stack:
        item, path, depth = stack.pop()
        where = f"{path}: " if path else ""
        if isinstance(item, _Rejected):
            raise StrictJSONError("non_finite_number" if "finite" in item.why else "number_out_of_range",
                                  where + item.why)
        if isinstance(item, str) and not _utf8(item):
            raise StrictJSONError("invalid_json", where + "a string holds an unpaired surrogate (\\ud800-\\udfff)")
        if isinstance(item, dict | list):
            if depth >= MAX_JSON_DEPTH:
                raise StrictJSONError("invalid_json", f"the body nests deeper than {MAX_JSON_DEPTH} levels")
            entries = item.items() if isinstance(item, dict) else enumerate(item)
            for key, sub in entries:
                if isinstance(key, str) and not _utf8(key):
                    raise StrictJSONError("invalid_json", where + "a key holds an unpaired surrogate")
                stack.append((sub, f"{path}.{key}" if path else str(key), depth + 1))
    return value


def _json_type(content_type: str | None) -> bool:
    if not content_type:
        return True  # FastAPI reads a body without a type as JSON
    main = content_type.split(";", 1)[0].strip().lower()
    return main == "application/json" or (main.startswith("application/") and main.endswith("+json"))


class BodyGuard:
    """ASGI middleware: the body size limit for every request and strict JSON for the API's.

    A body over the limit is answered at once (413), from its Content-Length when it declares
    one; the rest of it is then read and dropped, at most ``drain_bytes`` in all and for at most
    ``drain_timeout`` s, before the answer ends and the connection closes. Closing a socket with
    unread bytes in it resets the connection, and a client that sends its whole body before
    reading (most do) would get that reset instead of its 413."""

    def __init__(self, app: ASGIApp, max_body_bytes: int, json_prefix: str = "/api/",
                 drain_bytes: int = 16 * 2**20, drain_timeout: float = 30.0):
        # drain_timeout also bounds reading a body that is not refused (408 past it)
        self.app, self.max_body_bytes, self.json_prefix = app, max_body_bytes, json_prefix
        self.drain_bytes, self.drain_timeout = drain_bytes, drain_timeout

    async def _refuse(self, scope: Scope, receive: Receive, send: Send, status: int, code: str, message: str,
                      close: bool = False) -> None:
        headers = {"Connection": "close"} if close else None
        await error_response(status, code, message, headers=headers)(scope, receive, send)

    async def _refuse_unread(self, headers: Headers, receive: Receive, send: Send, status: int, code: str,
                             message: str, read: int = 0) -> None:
        """Refuse a request whose body is not (all) read yet: the whole answer first, then the
        drain, then the end of the response, which closes the connection."""
        response = error_response(status, code, message, headers={"Connection": "close"})
        await send({"type": "http.response.start", "status": status, "headers": response.raw_headers})
        # complete for the client (it has a Content-Length); the connection stays open meanwhile
        await send({"type": "http.response.body", "body": response.body, "more_body": True})
        declared = headers.get("content-length", "").strip()
        fits = not declared.isdigit() or int(declared) <= self.drain_bytes
        # a client that waits for "100 Continue" sends no body: there is nothing to drain
        if fits and "100-continue" not in headers.get("expect", "").lower():
            await self._drain(receive, read)
        await send({"type": "http.response.body", "body": b"", "more_body": False})

    async def _drain(self, receive: Receive, read: int) -> None:
        try:
            async with asyncio.timeout(self.drain_timeout):
                while read <= self.drain_bytes:
                    message = await receive()
                    if message["type"] != "http.request":  # the client went away
                        return
                    read += len(message.get("body", b""))
                    if not message.get("more_body", False):
                        return
        except TimeoutError:
            return  # too slow: the connection closes with the rest unread

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = Headers(scope=scope)
        if "transfer-encoding" in headers and "content-length" in headers:
            # two framings: a proxy in front may have read the body by the other one (request
            # smuggling), so neither is trusted
            await self._refuse_unread(headers, receive, send, 400, "ambiguous_framing",
                                      "the request has both Content-Length and Transfer-Encoding; send one")
            return
        limit = self.max_body_bytes
        too_large = f"the request body is larger than {limit} bytes"
        declared = headers.get("content-length")
        if declared is not None and declared.strip().isdigit() and int(declared) > limit:
            # refused from the header alone, before any of the body is read
            await self._refuse_unread(headers, receive, send, 413, "body_too_large", too_large)
            return
        chunks: list[bytes] = []
        size, more, over = 0, True, False
        try:
            # a body that trickles in holds a connection and a task: it has body_timeout s in all
            async with asyncio.timeout(self.drain_timeout):
                while more:
                    message = await receive()
                    if message["type"] != "http.request":  # the client went away
                        return
                    chunk = message.get("body", b"")
                    size += len(chunk)
                    more = message.get("more_body", False)
                    if size > limit:
                        over = True
                        break
                    chunks.append(chunk)
        except TimeoutError:
            await self._refuse(scope, receive, send, 408, "request_timeout",
                               f"the request body did not arrive within {self.drain_timeout:g} s", close=True)
            return
        if over:
            if more:
                await self._refuse_unread(headers, receive, send, 413, "body_too_large", too_large, read=size)
            else:
                await self._refuse(scope, receive, send, 413, "body_too_large", too_large, close=True)
            return
        body = b"".join(chunks)
        if body and scope["path"].startswith(self.json_prefix) and scope["method"] in ("POST", "PUT", "PATCH"):
            if not _json_type(headers.get("content-type")):
                await self._refuse(scope, receive, send, 415, "unsupported_media_type",
                                   "the API takes JSON bodies (Content-Type: application/json)")
                return
            try:
                parse_strict_json(body)
            except StrictJSONError as err:
                await self._refuse(scope, receive, send, 422, err.code, err.message)
                return

        replayed = False

        async def replay() -> Message:
            nonlocal replayed
            if not replayed:
                replayed = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        await self.app(scope, replay, send)


# -- sessions -----------------------------------------------------------------------------------
class SessionLimits:
    """Admission, idle expiry and the events quota of one server's sessions."""

    def __init__(self, manager: SessionManager, limits: Limits, clock: Callable[[], float] = time.monotonic):
        self.manager, self.limits, self.clock = manager, limits, clock
        self.max_sessions = manager.config.max_sessions
        self._lock = threading.Lock()
        self._quota_lock = threading.Lock()
        self._owner: dict[str, str] = {}  # session id -> client address
        self._seen: dict[str, float] = {}  # session id -> clock time of the last request about it
        self._expired: set[str] = set()
        self._started: dict[str, deque[float]] = {}  # client -> clock times of its recent sessions
        self._left: dict[str, float] = {}  # session id -> clock time its page said it was closing

    # -- admission ----------------------------------------------------------------------------
    def create(self, client: str, participant: str | None = None, seed: int | None = None, start: bool = True,
               **enrol: Any) -> WebSession:
        """A new session for ``client``; ``enrol``: the URL's IDs and the consent (see
        :meth:`SessionManager.create`). ``start=False``: enrolled only (the start page's
        agreement); it takes a slot only at :meth:`start`."""
        if start:
            self._settle()
        with self._lock:
            now = self.clock()
            started = self._started.setdefault(client, deque())
            while started and now - started[0] >= 3600:
                started.popleft()
            shared = self.limits.shared(client)
            if not shared and len(started) >= self.limits.max_new_sessions_per_hour:
                wait = math.ceil(3600 - (now - started[0]))
                raise ApiError(
                    429, "session_rate_limited",
                    f"this address started {len(started)} sessions in the last hour (limit "
                    f"{self.limits.max_new_sessions_per_hour}); try again in {wait} s",
                    headers={"Retry-After": str(max(1, wait))},
                )
            if start:
                self._check_room(client)
            else:  # enrolled, not started: bounded per address too (they hold memory, not a slot)
                waiting = [s for s in self.manager.all() if s.active and not s.begun
                           and self._owner.get(s.id) == client]
                if not shared and len(waiting) >= 4 * self.limits.max_sessions_per_client:
                    raise ApiError(429, "too_many_sessions",
                                   f"this address has {len(waiting)} sessions waiting for Start; start or close one",
                                   headers={"Retry-After": "60"})
            session = self.manager.create(participant=participant, seed=seed, start=start, **enrol)
            self._owner[session.id] = client
            self._seen[session.id] = now
            started.append(now)
            return session

    def start(self, session: WebSession, client: str) -> WebSession:
        """Start an enrolled session (the page's Start): the per-client and server limits apply now."""
        if session.begun:
            return session
        self._settle()
        with self._lock:
            self._check_room(self._owner.get(session.id, client))
            self._seen[session.id] = self.clock()
            self._left.pop(session.id, None)
            return self.manager.begin(session)

    def _settle(self) -> None:
        cancelled = self.expire_idle()
        deadline = time.monotonic() + self.limits.settle_seconds
        for s in cancelled:  # their slots are free once their episodes have stopped
            s.join(max(0.0, deadline - time.monotonic()))

    def _check_room(self, client: str) -> None:
        live = [s for s in self.manager.all() if s.running]
        mine = [s for s in live if self._owner.get(s.id) == client]
        retry = str(max(1, math.ceil(min(self.limits.idle_timeout, 60))))
        if not self.limits.shared(client) and len(mine) >= self.limits.max_sessions_per_client:
            raise ApiError(
                429, "too_many_sessions",
                f"this address has {len(mine)} sessions in progress (limit "
                f"{self.limits.max_sessions_per_client} per client); finish or close one first",
                headers={"Retry-After": retry},
            )
        if len(live) >= self.max_sessions:
            raise ApiError(
                503, "server_full",
                f"{len(live)} sessions are in progress (limit {self.max_sessions}); try again later",
                headers={"Retry-After": retry},
            )

    def forget_quiet_clients(self) -> None:
        """Drop the start times older than an hour (bounded memory for many addresses)."""
        with self._lock:
            now = self.clock()
            for client in list(self._started):
                times = self._started[client]
                while times and now - times[0] >= 3600:
                    times.popleft()
                if not times:
                    del self._started[client]

    # -- idle expiry --------------------------------------------------------------------------
    def touch(self, sid: str) -> None:
        with self._lock:
            self._seen[sid] = self.clock()
            self._left.pop(sid, None)  # a page of it is open again (the next page, a reload)

    def leave(self, sid: str) -> None:
        """The session's page is going away (a beacon on unload): unless a page of it asks
        again within ``reconnect_grace`` s, the session is cancelled and its slot freed."""
        with self._lock:
            self._left[sid] = self.clock()

    def expire_idle(self) -> list[WebSession]:
        """Cancel the sessions in progress that nobody asked about for ``idle_timeout`` s, and
        those whose page closed ``reconnect_grace`` s ago without coming back."""
        cancelled = []
        with self._lock:
            now = self.clock()
            for s in self.manager.all():
                if not s.active or s.id in self._expired:
                    continue
                seen = self._seen.setdefault(s.id, now)
                left = self._left.get(s.id)
                if now - seen > self.limits.idle_timeout:
                    why = f"no request about this session for {self.limits.idle_timeout:g} s (idle timeout)"
                elif left is not None and now - left > self.limits.reconnect_grace:
                    why = (f"its page was closed and did not come back within "
                           f"{self.limits.reconnect_grace:g} s (page closed)")
                else:
                    continue
                self._expired.add(s.id)
                self._left.pop(s.id, None)
                cancelled.append((s, why))
        for s, why in cancelled:
            s.cancel(why)
        return [s for s, _ in cancelled]

    # -- events quota -------------------------------------------------------------------------
    @contextmanager
    def events_quota(self, session: WebSession, size: int) -> Iterator[None]:
        """Hold while writing ``size`` bytes of client events: refused (413) past the quota."""
        with self._quota_lock:
            path = session.dir / "events.jsonl"
            used = path.stat().st_size if path.exists() else 0
            quota = self.limits.events_quota_bytes
            if used + size > quota:
                raise ApiError(
                    413, "session_quota_exceeded",
                    f"this session's event log is full ({used} of {quota} bytes); no more events are kept",
                )
            yield


def event_lines_size(events: list[dict]) -> int:
    """Bytes ``events`` add to events.jsonl (an upper bound); ValueError for a non-finite number."""
    return sum(len(json.dumps(e, allow_nan=False)) + EVENT_LINE_OVERHEAD for e in events)
