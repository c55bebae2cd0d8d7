"""One shape for every error the study server answers with.

Whatever goes wrong (unknown route, wrong method, malformed or oversized body, a limit hit, a
refused answer, a bug), the body is::

    {"error": {"status": 422, "code": "invalid_request", "message": "round: ...", "fields": [...]}}

``code`` is a stable machine-readable word, ``message`` a sentence for people; ``fields``
appears only on validation errors. The offending input is never echoed back: it may not even be
representable as JSON (NaN, broken UTF-8).
"""

from __future__ import annotations

import errno
import logging
import time
from collections.abc import Callable
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from activeintent.memo import BoundedCache
from activeintent.signals import AnswerRejected

log = logging.getLogger("activeintent.web")

# the code an error gets when nothing more specific is known
DEFAULT_CODES = {
    400: "bad_request",
    404: "not_found",
    405: "method_not_allowed",
    409: "conflict",
    413: "too_large",
    415: "unsupported_media_type",
    422: "invalid_request",
    429: "too_many_requests",
    500: "internal_error",
    503: "unavailable",
    408: "request_timeout",
}


class RepeatGate:
    """One line of each kind per ``every`` seconds: :meth:`admit` says whether this one passes and,
    when it does, what to add to it about those held back since the last. It remembers the last
    ``size`` kinds (a forgotten kind passes again)."""

    def __init__(self, every: float = 10.0, clock: Callable[[], float] = time.monotonic, size: int = 256):
        self.every, self.clock = every, clock
        self._last: BoundedCache[str, float] = BoundedCache(size)
        self._held: BoundedCache[str, int] = BoundedCache(size)

    def admit(self, kind: str) -> str | None:
        """None: held back; else the note for the line ('' when none was held back)."""
        now = self.clock()
        last = self._last.get(kind)
        if last is not None and now - last < self.every:
            self._held.put(kind, (self._held.get(kind) or 0) + 1)
            return None
        held = self._held.get(kind) or 0
        self._held.put(kind, 0)
        self._last.put(kind, now)
        if not held:
            return ""
        since = f" in the last {now - last:.0f} s" if last is not None else ""
        return f" (and {held} more like it{since})"


class RateLimitedLog:
    """At most one line per ``every`` seconds of each kind, the next one saying how many were
    left out: what a flood of bad connections makes the server say stays a few lines."""

    def __init__(self, logger: logging.Logger, every: float = 10.0, clock: Callable[[], float] = time.monotonic):
        self.logger = logger
        self.gate = RepeatGate(every, clock)

    def warning(self, kind: str, message: str, *args: Any) -> bool:
        """Log ``message % args`` unless a line of ``kind`` was logged less than ``every`` s ago."""
        note = self.gate.admit(kind)
        if note is None:
            return False
        self.logger.warning(message + note.replace("%", "%%"), *args)
        return True


_limited = RateLimitedLog(log)


class ApiError(Exception):
    """An error answer with a status, a code and a message (and optional extra headers)."""

    def __init__(self, status: int, code: str, message: str, headers: dict[str, str] | None = None):
        super().__init__(message)
        self.status, self.code, self.message = status, code, message
        self.headers = headers or {}


def error_body(status: int, code: str | None, message: str, **extra: Any) -> dict:
    return {"error": {"status": status, "code": code or DEFAULT_CODES.get(status, "error"),
                      "message": message, **extra}}


def error_response(status: int, code: str | None, message: str, headers: dict[str, str] | None = None,
                   **extra: Any) -> JSONResponse:
    return JSONResponse(error_body(status, code, message, **extra), status_code=status, headers=headers)


def _validation_fields(exc: RequestValidationError) -> tuple[str, list[dict]]:
    problems, fields = [], []
    for err in exc.errors():
        loc = [str(p) for p in err.get("loc", ()) if p != "body"]
        where = ".".join(loc)
        msg = str(err.get("msg"))
        problems.append(f"{where}: {msg}" if where else msg)
        fields.append({"loc": where, "msg": msg, "type": str(err.get("type"))})
    return "invalid request: " + "; ".join(problems), fields


def install_error_handlers(app: FastAPI) -> None:
    """Route every error the app can raise through :func:`error_response`."""

    @app.exception_handler(ApiError)
    async def _api_error(request: Request, exc: ApiError):
        return error_response(exc.status, exc.code, exc.message, headers=exc.headers)

    @app.exception_handler(AnswerRejected)
    async def _rejected(request: Request, exc: AnswerRejected):
        code = exc.code or {409: "conflict", 422: "invalid_answer", 503: "server_full"}.get(exc.status)
        return error_response(exc.status, code, str(exc))

    @app.exception_handler(RequestValidationError)
    async def _invalid(request: Request, exc: RequestValidationError):
        message, fields = _validation_fields(exc)
        return error_response(422, "invalid_request", message, fields=fields)

    @app.exception_handler(StarletteHTTPException)
    async def _http(request: Request, exc: StarletteHTTPException):
        # routing (404, 405), static files and FastAPI's own body errors
        message = exc.detail if isinstance(exc.detail, str) else DEFAULT_CODES.get(exc.status_code, "error")
        return error_response(exc.status_code, None, message, headers=getattr(exc, "headers", None))

    @app.exception_handler(Exception)
    async def _bug(request: Request, exc: Exception):
        if isinstance(exc, OSError) and exc.errno in (errno.EMFILE, errno.ENFILE):
            # not a bug: the process is out of file descriptors for now; one line, no traceback each
            _limited.warning("fds", "out of file descriptors on %s %s: answered 503", request.method, request.url.path)
            return error_response(503, "server_busy", "the server is out of resources for the moment; "
                                  "try again in a few seconds", headers={"Retry-After": "5"})
        log.exception("unhandled error on %s %s", request.method, request.url.path)
        return error_response(500, "internal_error", "the server failed on this request; it is logged")
