"""One shape for every error the study server answers with.

Whatever goes wrong (unknown route, wrong method, malformed or oversized body, a limit hit, a
refused answer, a bug), the body is::

    {"error": {"status": 422, "code": "invalid_request", "message": "round: ...", "fields": [...]}}

``code`` is a stable machine-readable word, ``message`` a sentence for people; ``fields``
appears only on validation errors. The offending input is never echoed back: it may not even be
representable as JSON (NaN, broken UTF-8).
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException

from activeintent.users.human import AnswerRejected

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
}


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
        code = {409: "conflict", 422: "invalid_answer", 503: "server_full"}.get(exc.status)
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
        log.exception("unhandled error on %s %s", request.method, request.url.path)
        return error_response(500, "internal_error", "the server failed on this request; it is logged")
