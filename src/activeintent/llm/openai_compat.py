"""Any server speaking the chat-completions API (OpenAI, vLLM, Ollama, llama.cpp's server,
LM Studio) through the official ``openai`` SDK.

Structured output asks for ``response_format: json_schema``; a server that rejects it is asked
with ``json_object``, then with plain text (the schema is always in the prompt too); the answer
is validated above this layer and repaired when it does not parse. Transient failures are
retried here with exponential backoff and jitter, then raised as typed errors.
"""

from __future__ import annotations

import base64
import json
import os
import time
from collections.abc import Callable
from typing import Any

import openai

from activeintent.llm.backend import (
    Backend,
    ChatRequest,
    Completion,
    schema_instruction,
    with_instruction,
)
from activeintent.llm.base import (
    ImagePart,
    Message,
    ModelError,
    ModelUnavailableError,
    TransientModelError,
)
from activeintent.llm.retry import RetryOutcome, RetryPolicy, Transient, run_with_retry

# Tried in this order; a server that rejects one (HTTP 400/422) is asked with the next.
# "json_object_schema" is json_object plus a "schema" key, the form llama-cpp-python's server
# takes (it turns the schema into a grammar).
FORMAT_MODES = ("json_schema", "json_object_schema", "json_object", "text")
DUMMY_API_KEY = "sk-no-key-needed"


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
        self.accepts_images = accepts_images
        self.seed = seed
        self.retry = retry or RetryPolicy()
        self._sleep = sleep
        # Retries are ours (typed errors, seeded jitter), so the SDK's own are off.
        self.client = openai.OpenAI(
            api_key=api_key, base_url=base_url, timeout=timeout_s, max_retries=0
        )
        self._format_mode = 0  # index into FORMAT_MODES, lowered when the server refuses one
        self._max_tokens_field = "max_tokens"

    @property
    def where(self) -> str:
        return self.base_url or "api.openai.com"

    def complete(self, request: ChatRequest) -> Completion:
        structured = request.json_schema is not None
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
            try:
                return self.client.chat.completions.create(**kwargs)
            except openai.APITimeoutError as exc:
                raise Transient("timed out") from exc
            except openai.APIConnectionError as exc:
                cause = exc.__cause__
                refused = cause is not None and type(cause).__name__ == "ConnectError"
                raise Transient(f"connection failed ({cause or exc})", unreachable=refused) from exc
            except openai.APIStatusError as exc:
                raise self._classify(exc, format_requested=fmt is not None) from exc
            except (openai.APIResponseValidationError, json.JSONDecodeError) as exc:
                raise Transient(f"malformed or truncated response body ({exc})") from exc

        outcome = run_with_retry(lambda: _checked(attempt()), self.retry, sleep=self._sleep)
        if isinstance(outcome, RetryOutcome):
            summary = "; ".join(outcome.errors)
            if outcome.unreachable:
                raise ModelUnavailableError(
                    f"openai:{self.model_name}: nothing answers at {self.where} "
                    f"after {outcome.attempts} attempts ({summary})"
                )
            raise TransientModelError(
                f"openai:{self.model_name} at {self.where} failed {outcome.attempts} times: {summary}",
                attempts=outcome.attempts,
            )
        response, attempts = outcome
        choice = response.choices[0]
        usage = response.usage
        return Completion(
            text=choice.message.content or "",
            prompt_tokens=usage.prompt_tokens if usage else 0,
            completion_tokens=usage.completion_tokens if usage else 0,
            attempts=attempts,
            finish_reason=choice.finish_reason,
        )

    def _classify(self, exc: openai.APIStatusError, *, format_requested: bool) -> Exception:
        code, detail = exc.status_code, _error_detail(exc)
        # Some servers answer an unknown response_format with 500 (llama-cpp-python's does):
        # a refusal to try another format for, not a transient failure.
        if code in (400, 422) or (format_requested and "response_format" in detail):
            return _Refused(code, detail)
        if code in (408, 409, 425, 429) or code >= 500:
            return Transient(f"HTTP {code}: {detail}")
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


def _checked(response: Any) -> Any:
    # A body cut short may still parse as a JSON prefix object with no choices.
    if not getattr(response, "choices", None):
        raise Transient(f"response without choices: {str(response)[:200]}")
    return response


def _error_detail(exc: openai.APIStatusError) -> str:
    body = exc.body
    if isinstance(body, dict):
        err = body.get("error", body)
        if isinstance(err, dict):
            return str(err.get("message") or err)
        return str(err)
    return str(exc.message)
