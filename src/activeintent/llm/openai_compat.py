"""Any server speaking the chat-completions API (OpenAI, vLLM, Ollama, llama.cpp's server,
LM Studio) through the official ``openai`` SDK.

Structured output asks for ``response_format: json_schema``; a server that rejects it is asked
with ``json_object``, then with plain text (the schema is always in the prompt too); the answer
is validated above this layer and repaired when it does not parse. Transient failures are
retried here with exponential backoff and jitter, then raised as typed errors.

Every call is bounded (:class:`CallLimits`): a connect timeout, an overall deadline over all its
attempts and waits (enforced on every socket read and write, so a server that drips bytes
cannot stretch it), and a cap on the bytes read. Bodies are asked for uncompressed and a
compressed one is refused unread (the cap counts bytes on the wire); redirects are refused, not
followed. The body is parsed here, strictly: anything but UTF-8 JSON of the chat-completions
shape, nested at most MAX_JSON_DEPTH deep, with finite, whole token counts is a ModelError.
"""

from __future__ import annotations

import base64
import email.utils
import json
import os
import threading
import time
import urllib.request
from collections.abc import Callable
from typing import Any
from urllib.parse import urlsplit

import httpcore2
import httpx2
import openai
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from activeintent.llm.backend import (
    Backend,
    ChatRequest,
    Completion,
    loads_bounded,
    schema_instruction,
    with_instruction,
)
from activeintent.llm.base import (
    ImagePart,
    Message,
    ModelError,
    ModelRedirectError,
    ModelUnavailableError,
    TransientModelError,
)
from activeintent.llm.retry import RetryOutcome, RetryPolicy, Transient, run_with_retry

# Tried in this order; a server that rejects one (HTTP 400/422) is asked with the next.
# "json_object_schema" is json_object plus a "schema" key, the form llama-cpp-python's server
# takes (it turns the schema into a grammar).
FORMAT_MODES = ("json_schema", "json_object_schema", "json_object", "text")
DUMMY_API_KEY = "sk-no-key-needed"
DEFAULT_BASE_URL = "https://api.openai.com/v1"  # the SDK's, when no base URL is given

# Environment variables that set CallLimits (forwarded to bench workers, Ray's too).
ENV_CONNECT_S = "ACTIVEINTENT_MODEL_CONNECT_S"
ENV_DEADLINE_S = "ACTIVEINTENT_MODEL_DEADLINE_S"
ENV_MAX_BYTES = "ACTIVEINTENT_MODEL_MAX_BYTES"


class CallLimits(BaseModel):
    """Bounds of one model call (``complete``: every attempt, retry wait and format fallback)."""

    connect_s: float = Field(default=10.0, gt=0)  # to open the connection
    deadline_s: float = Field(default=180.0, gt=0)  # the whole call, however the server behaves
    max_response_bytes: int = Field(default=8 * 2**20, gt=0)  # read per attempt (headers and body)

    @classmethod
    def from_env(cls) -> CallLimits:
        """The defaults, overridden by ACTIVEINTENT_MODEL_CONNECT_S / _DEADLINE_S / _MAX_BYTES."""
        values: dict[str, Any] = {}
        for field, name in (("connect_s", ENV_CONNECT_S), ("deadline_s", ENV_DEADLINE_S),
                            ("max_response_bytes", ENV_MAX_BYTES)):
            if os.environ.get(name):
                values[field] = os.environ[name]
        try:
            return cls.model_validate(values)
        except ValidationError as err:
            raise ValueError(f"bad model call limit in the environment ({ENV_CONNECT_S}, {ENV_DEADLINE_S}, "
                             f"{ENV_MAX_BYTES}): {err.errors()[0]['msg']}") from None


class _Budget(threading.local):
    """What the current attempt may still spend: time until ``deadline`` and ``left`` bytes.
    ``tripped`` says which bound stopped it ("deadline" | "size")."""

    deadline: float | None = None
    left: int = 0
    tripped: str | None = None

    def start(self, deadline: float, max_bytes: int) -> None:
        self.deadline, self.left, self.tripped = deadline, max_bytes, None

    def timeout(self, timeout: float | None, error: type[Exception]) -> float | None:
        if self.deadline is None:
            return timeout
        remaining = self.deadline - time.monotonic()
        if remaining <= 0:
            self.tripped = "deadline"
            raise error("the call's deadline has passed")
        return remaining if timeout is None else min(timeout, remaining)

    def spend(self, n: int) -> None:
        if self.deadline is None:
            return
        self.left -= n
        if self.left < 0:
            self.tripped = "size"
            raise httpcore2.ReadError("response larger than the cap")


class _BoundedStream(httpcore2.NetworkStream):
    """A connection whose every read and write ends by the deadline and counts its bytes."""

    def __init__(self, inner: httpcore2.NetworkStream, budget: _Budget) -> None:
        self.inner, self.budget = inner, budget

    def read(self, max_bytes: int, timeout: float | None = None) -> bytes:
        data = self.inner.read(max_bytes, self.budget.timeout(timeout, httpcore2.ReadTimeout))
        self.budget.spend(len(data))
        return data

    def write(self, buffer: bytes, timeout: float | None = None) -> None:
        self.inner.write(buffer, self.budget.timeout(timeout, httpcore2.WriteTimeout))

    def close(self) -> None:
        self.inner.close()

    def start_tls(self, ssl_context: Any, server_hostname: str | None = None,
                  timeout: float | None = None) -> httpcore2.NetworkStream:
        tls = self.inner.start_tls(ssl_context, server_hostname, self.budget.timeout(timeout, httpcore2.ConnectTimeout))
        return _BoundedStream(tls, self.budget)

    def get_extra_info(self, info: str) -> Any:
        return self.inner.get_extra_info(info)


class _BoundedBackend(httpcore2.NetworkBackend):
    def __init__(self, budget: _Budget) -> None:
        self.inner, self.budget = httpcore2.SyncBackend(), budget

    def connect_tcp(self, host: str, port: int, timeout: float | None = None, local_address: str | None = None,
                    socket_options: Any = None) -> httpcore2.NetworkStream:
        stream = self.inner.connect_tcp(host, port, self.budget.timeout(timeout, httpcore2.ConnectTimeout),
                                        local_address, socket_options)
        return _BoundedStream(stream, self.budget)

    def connect_unix_socket(self, path: str, timeout: float | None = None,
                            socket_options: Any = None) -> httpcore2.NetworkStream:
        stream = self.inner.connect_unix_socket(path, self.budget.timeout(timeout, httpcore2.ConnectTimeout),
                                                socket_options)
        return _BoundedStream(stream, self.budget)

    def sleep(self, seconds: float) -> None:
        self.inner.sleep(seconds)


def _bounded_client(base_url: str | None, budget: _Budget, limits: CallLimits, read_s: float) -> httpx2.Client:
    """The SDK's HTTP client, reading through :class:`_BoundedBackend`. httpx2 takes no network
    backend, so the pool it built gets ours (a test fails should that attribute go). An explicit
    transport turns off the environment's proxies: the one for this URL is passed on."""
    url = urlsplit(base_url or "https://api.openai.com/v1")
    proxies = urllib.request.getproxies()
    proxy = None if urllib.request.proxy_bypass(url.hostname or "") else proxies.get(url.scheme)
    transport = _GuardedTransport(proxy=proxy)
    transport._pool._network_backend = _BoundedBackend(budget)  # noqa: SLF001
    return openai.DefaultHttpxClient(transport=transport, timeout=httpx2.Timeout(read_s, connect=limits.connect_s),
                                     follow_redirects=False)


class _Refusal(openai.OpenAIError):
    """An answer this client will not read (the SDK passes its own errors through unwrapped)."""


class _Compressed(_Refusal):
    pass


class _Redirected(_Refusal):
    def __init__(self, code: int, location: str) -> None:
        super().__init__(f"HTTP {code} redirect")
        self.code, self.location = code, location


class _GuardedTransport(httpx2.HTTPTransport):
    """Asks for an uncompressed body and refuses any other before reading a byte of it (the size
    cap counts bytes on the wire: a small gzip body could inflate to gigabytes past it); refuses
    redirects, which would send the whole prompt to another server."""

    def handle_request(self, request: httpx2.Request) -> httpx2.Response:
        request.headers["Accept-Encoding"] = "identity"
        response = super().handle_request(request)
        encoding = response.headers.get("content-encoding", "").strip().lower()
        if encoding not in ("", "identity"):
            response.close()
            raise _Compressed(encoding)
        if 300 <= response.status_code < 400:
            response.close()
            raise _Redirected(response.status_code, response.headers.get("location", ""))
        return response


class _Strict(BaseModel):
    """Parts of a chat-completions body; strict, so a wrong type ("11" tokens) is not coerced."""

    model_config = ConfigDict(strict=True)


class _Message(_Strict):
    content: str | None = None


class _Choice(_Strict):
    message: _Message
    finish_reason: str | None = None


class _Usage(_Strict):
    prompt_tokens: int = Field(default=0, ge=0)
    completion_tokens: int = Field(default=0, ge=0)


class _Answer(_Strict):
    """The part of a chat-completions body we use."""

    choices: list[_Choice] = Field(min_length=1)
    usage: _Usage | None = None


def _not_a_number(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def parse_answer(body: bytes) -> _Answer:
    """The body of a 200, or a ValueError saying what is wrong with it."""
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"the body is not UTF-8 ({exc.reason} at byte {exc.start})") from None
    try:
        data = loads_bounded(text, parse_constant=_not_a_number)
    except ValueError as exc:
        raise ValueError(f"the body is not JSON ({exc}): {text[:80]!r}") from None
    try:
        return _Answer.model_validate(data)
    except ValidationError as exc:
        problems = "; ".join(f"{'.'.join(map(str, e['loc'])) or 'body'}: {e['msg']}" for e in exc.errors()[:3])
        raise ValueError(f"the body is not a chat completion ({problems})") from None


def retry_after_s(headers: Any) -> float | None:
    """Retry-After in seconds (a number or an HTTP date), None when absent or unreadable."""
    value = (headers.get("retry-after") or "").strip() if headers is not None else ""
    if not value:
        return None
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, when.timestamp() - time.time())


def encode_messages(messages: list[Message]) -> list[dict[str, Any]]:
    """Chat-completions messages; images become base64 PNG data URLs in content parts."""
    out: list[dict[str, Any]] = []
    for m in messages:
        if isinstance(m.content, str):
            out.append({"role": m.role, "content": m.content})
            continue
        parts: list[dict[str, Any]] = []
        for p in m.content:
            if isinstance(p, ImagePart):
                url = "data:image/png;base64," + base64.b64encode(p.png).decode("ascii")
                parts.append({"type": "image_url", "image_url": {"url": url}})
            else:
                parts.append({"type": "text", "text": p.text})
        out.append({"role": m.role, "content": parts})
    return out


def response_format(mode: str, request: ChatRequest) -> dict[str, Any] | None:
    if mode == "json_schema":
        return {
            "type": "json_schema",
            "json_schema": {
                "name": (request.schema_name or "answer")[:64],
                "schema": request.json_schema,
                "strict": False,  # pydantic schemas with defaults are not "strict"-compatible
            },
        }
    if mode == "json_object_schema":
        return {"type": "json_object", "schema": request.json_schema}
    if mode == "json_object":
        return {"type": "json_object"}
    return None


class OpenAIBackend(Backend):
    """``openai:<model-name>``. ``base_url`` (else ``OPENAI_BASE_URL``) points at the server;
    the key comes from ``OPENAI_API_KEY`` and may be absent for a local server."""

    kind = "openai"

    def __init__(
        self,
        model: str,
        *,
        base_url: str | None = None,
        api_key: str | None = None,
        timeout_s: float = 120.0,
        retry: RetryPolicy | None = None,
        accepts_images: bool = True,
        seed: int = 0,
        sleep: Callable[[float], None] = time.sleep,
        limits: CallLimits | None = None,
    ) -> None:
        if not model:
            raise ValueError("openai:<model-name> needs a model name, e.g. openai:gpt-4o-mini")
        base_url = base_url or os.environ.get("OPENAI_BASE_URL") or None
        api_key = api_key or os.environ.get("OPENAI_API_KEY")
        if not api_key:
            if base_url is None:
                raise ModelUnavailableError(
                    f"openai:{model} needs OPENAI_API_KEY, or --base-url / OPENAI_BASE_URL "
                    "for a local server (which takes a dummy key)"
                )
            api_key = DUMMY_API_KEY
        self.model_name = model
        self.base_url = base_url
        self.server = (base_url or DEFAULT_BASE_URL).rstrip("/")
        self.accepts_images = accepts_images
        self.seed = seed
        self.retry = retry or RetryPolicy()
        self._sleep = sleep
        self.limits = limits or CallLimits.from_env()
        self._budget = _Budget()
        self._deadline = 0.0
        # Retries are ours (typed errors, seeded jitter), so the SDK's own are off. timeout_s
        # bounds each wait for a byte; the deadline the whole call.
        self.client = openai.OpenAI(
            api_key=api_key, base_url=base_url, max_retries=0,
            http_client=_bounded_client(base_url, self._budget, self.limits, timeout_s),
        )
        self._format_mode = 0  # index into FORMAT_MODES, lowered when the server refuses one
        self._max_tokens_field = "max_tokens"

    @property
    def where(self) -> str:
        return self.base_url or "api.openai.com"

    def complete(self, request: ChatRequest) -> Completion:
        structured = request.json_schema is not None
        self._deadline = time.monotonic() + self.limits.deadline_s
        while True:
            mode = FORMAT_MODES[self._format_mode] if structured else "text"
            messages = request.messages
            if structured:
                messages = with_instruction(messages, schema_instruction(request.json_schema or {}))
            try:
                return self._complete_with_retry(request, encode_messages(messages), mode)
            except _Refused as exc:
                detail = exc.detail
                if "max_completion_tokens" in detail and self._max_tokens_field == "max_tokens":
                    self._max_tokens_field = "max_completion_tokens"
                    continue
                if structured and mode != "text":
                    self._format_mode += 1  # this server does not take that response_format
                    continue
                raise ModelError(f"openai:{self.model_name} at {self.where} refused: {detail}") from exc

    def _complete_with_retry(
        self, request: ChatRequest, messages: list[dict[str, Any]], mode: str
    ) -> Completion:
        kwargs: dict[str, Any] = {
            "model": self.model_name,
            "messages": messages,
            "temperature": request.temperature,
            self._max_tokens_field: request.max_tokens,
            "seed": request.seed,
        }
        fmt = response_format(mode, request) if request.json_schema is not None else None
        if fmt is not None:
            kwargs["response_format"] = fmt

        def attempt() -> Any:
            self._budget.start(self._deadline, self.limits.max_response_bytes)
            try:
                raw = self.client.chat.completions.with_raw_response.create(**kwargs)
            except _Compressed as exc:
                raise _TooLarge(f"openai:{self.model_name} at {self.where} sent a body compressed with {str(exc)[:40]!r} "
                                "although asked for none (Accept-Encoding: identity); compressed answers are not "
                                "read, since a small one can inflate past the size cap") from None
            except _Redirected as exc:
                raise self._redirect(exc) from None
            except openai.APITimeoutError as exc:
                raise self._bounded(exc) or Transient("timed out") from exc
            except openai.APIConnectionError as exc:
                cause = exc.__cause__
                refused = cause is not None and type(cause).__name__ == "ConnectError"
                raise self._bounded(exc) or Transient(f"connection failed ({cause or exc})", unreachable=refused) from exc
            except openai.APIStatusError as exc:
                raise self._classify(exc, format_requested=fmt is not None) from exc
            except (openai.APIResponseValidationError, json.JSONDecodeError) as exc:
                raise Transient(f"malformed or truncated response body ({exc})") from exc
            body = raw.http_response.content
            if len(body) > self.limits.max_response_bytes:  # decompressed past the cap
                raise _TooLarge(self._too_large())
            try:
                return parse_answer(body)
            except ValueError as exc:
                raise Transient(f"malformed or truncated response body: {exc}") from exc

        try:
            outcome = run_with_retry(attempt, self.retry, sleep=self._sleep, deadline=self._deadline)
        except _TooLarge as exc:
            raise ModelError(str(exc)) from None
        if isinstance(outcome, RetryOutcome):
            summary = "; ".join(outcome.errors)
            if outcome.unreachable:
                raise ModelUnavailableError(
                    f"openai:{self.model_name}: nothing answers at {self.where} "
                    f"after {outcome.attempts} attempts ({summary})"
                )
            if outcome.deadline_passed:
                raise TransientModelError(
                    f"openai:{self.model_name} at {self.where}: no answer within the call's deadline of "
                    f"{self.limits.deadline_s:g} s ({ENV_DEADLINE_S}) after {outcome.attempts} attempts: {summary}",
                    attempts=outcome.attempts,
                )
            raise TransientModelError(
                f"openai:{self.model_name} at {self.where} failed {outcome.attempts} times: {summary}",
                attempts=outcome.attempts,
            )
        answer, attempts = outcome
        choice = answer.choices[0]
        usage = answer.usage
        return Completion(
            text=choice.message.content or "",
            prompt_tokens=usage.prompt_tokens if usage else 0,
            completion_tokens=usage.completion_tokens if usage else 0,
            attempts=attempts,
            finish_reason=choice.finish_reason,
        )

    def _bounded(self, exc: Exception) -> Exception | None:
        """The error of an attempt our limits stopped (None: something else stopped it)."""
        if self._budget.tripped == "size":
            return _TooLarge(self._too_large())
        if self._budget.tripped == "deadline" or time.monotonic() >= self._deadline:
            return Transient(f"the {self.limits.deadline_s:g} s deadline passed", final=True)
        return None

    def _redirect(self, exc: _Redirected) -> ModelRedirectError:
        where = repr(exc.location[:300]) if exc.location else "(no Location header)"  # repr: escapes controls
        return ModelRedirectError(
            f"openai:{self.model_name} at {self.where} answered HTTP {exc.code}, a redirect to {where}; redirects "
            "are not followed (the prompt would go to another server): if you trust that server, give it as "
            "--base-url", location=exc.location[:300])

    def _too_large(self) -> str:
        return (f"openai:{self.model_name} at {self.where}: the answer is larger than the "
                f"{self.limits.max_response_bytes} bytes cap ({ENV_MAX_BYTES}); not read further")

    def _classify(self, exc: openai.APIStatusError, *, format_requested: bool) -> Exception:
        code, detail = exc.status_code, _error_detail(exc)
        # Some servers answer an unknown response_format with 500 (llama-cpp-python's does):
        # a refusal to try another format for, not a transient failure.
        if code in (400, 422) or (format_requested and "response_format" in detail):
            return _Refused(code, detail)
        if code in (408, 409, 425, 429) or code >= 500:
            return Transient(f"HTTP {code}: {detail}", retry_after=retry_after_s(exc.response.headers))
        where = f"openai:{self.model_name} at {self.where}: HTTP {code} {detail}"
        if code in (401, 403, 404):
            return ModelUnavailableError(where)
        return ModelError(where)

    def close(self) -> None:
        self.client.close()


class _Refused(Exception):
    """The server rejected the request itself (HTTP 400/422, or a refused response_format)."""

    def __init__(self, code: int, detail: str) -> None:
        super().__init__(f"HTTP {code}: {detail}")
        self.detail = detail


class _TooLarge(Exception):
    """An answer past the size cap, or compressed: not retried (the next would be the same)."""


def _error_detail(exc: openai.APIStatusError) -> str:
    body = exc.body
    if isinstance(body, dict):
        err = body.get("error", body)
        if isinstance(err, dict):
            return str(err.get("message") or err)
        return str(err)
    return str(exc.message)
