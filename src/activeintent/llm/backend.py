"""What every backend shares: one request in, one completion out; cache, accounting,
validation and repair rounds live in :class:`BackendModel` on top of a :class:`Backend`."""

from __future__ import annotations

import json
import re
import time
from abc import ABC, abstractmethod
from importlib.resources import files
from typing import Any

from pydantic import BaseModel, ValidationError

from activeintent.llm.accounting import CallRecord, Usage
from activeintent.llm.base import (
    AnswerTooDeepError,
    CacheMissError,
    ChatModel,
    ImagesNotSupportedError,
    Message,
    ModelError,
    StructuredOutputError,
    T,
    TextPart,
)
from activeintent.memo import memoized


@memoized(size=64, why="a template's name: the package's prompt files do not change while the process runs")
def prompt_template(name: str) -> str:
    """The text of prompt template ``name`` (package data: activeintent/prompts/NAME.txt), read
    once; an unknown name lists the known ones. The one reader of the templates."""
    folder = files("activeintent") / "prompts"
    path = folder / f"{name}.txt"
    if not path.is_file():
        available = sorted(p.name[:-4] for p in folder.iterdir() if p.name.endswith(".txt"))
        raise FileNotFoundError(f"No prompt template {name!r}; available: {', '.join(available)}")
    return path.read_text(encoding="utf-8")


class ChatRequest(BaseModel):
    """Everything that determines a model's answer (and so the response-cache key)."""

    messages: list[Message]
    temperature: float = 0.0
    max_tokens: int = 512
    seed: int = 0
    json_schema: dict[str, Any] | None = None  # structured output wanted
    schema_name: str | None = None

    @property
    def has_images(self) -> bool:
        return any(m.has_images for m in self.messages)


class Completion(BaseModel):
    text: str
    prompt_tokens: int = 0
    completion_tokens: int = 0
    attempts: int = 1
    finish_reason: str | None = None


class Backend(ABC):
    """One model server or in-process model. ``complete`` raises ModelError subclasses."""

    kind: str = "backend"  # "openai", "llama.cpp", "scripted"
    model_name: str = "model"
    server: str | None = None  # a model server's base URL (part of the cache key); None in-process
    accepts_images: bool = False
    seed: int = 0

    @abstractmethod
    def complete(self, request: ChatRequest) -> Completion:
        """One answer; for a request with ``json_schema`` the backend constrains output as best
        it can (grammar, response_format, or an instruction) — validation happens above."""

    def close(self) -> None:  # noqa: B027 - optional hook
        pass


def schema_instruction(json_schema: dict[str, Any]) -> str:
    return prompt_template("structured_instruction").format(
        schema=json.dumps(json_schema, separators=(",", ":"))
    )


def with_instruction(messages: list[Message], instruction: str) -> list[Message]:
    """Append ``instruction`` to the last user message (keeps user/assistant alternation, which
    some chat templates require)."""
    out = list(messages)
    for i in range(len(out) - 1, -1, -1):
        m = out[i]
        if m.role == "user":
            if isinstance(m.content, str):
                out[i] = Message(role="user", content=f"{m.content}\n\n{instruction}")
            else:
                out[i] = Message(role="user", content=[*m.content, TextPart(text=instruction)])
            return out
    return [*out, Message(role="user", content=instruction)]


_FENCE = re.compile(r"```(?:json)?\s*(.*?)```", re.DOTALL)


def extract_json(text: str) -> str:
    """The JSON object in an answer that may wrap it in prose or a code fence."""
    fenced = _FENCE.search(text)
    if fenced:
        text = fenced.group(1)
    start, end = text.find("{"), text.rfind("}")
    if start == -1 or end < start:
        return text.strip()
    return text[start : end + 1]


MAX_JSON_DEPTH = 64  # nesting of arrays and objects in a model's JSON; answers need a handful
# A string, its closing quote optional: an unterminated one runs to the end, so every character
# is consumed once (linear, whatever the quotes and backslashes).
_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"?', re.DOTALL)


def json_depth(text: str) -> int:
    """How deeply the arrays and objects of a JSON text nest (brackets inside strings do not
    count), without parsing it: linear, no recursion, so any size and depth is safe to ask."""
    import numpy as np

    outside = _JSON_STRING.sub("", text).encode("utf-8", "replace")
    b = np.frombuffer(outside, dtype=np.uint8)
    step = ((b == ord("[")) | (b == ord("{"))).astype(np.int64) - ((b == ord("]")) | (b == ord("}")))
    return int(np.cumsum(step).max(initial=0))


class TooDeep(ValueError):
    """JSON nested deeper than allowed."""


def loads_bounded(text: str, *, max_depth: int = MAX_JSON_DEPTH, **kwargs: Any) -> Any:
    """``json.loads`` for untrusted text: :class:`TooDeep` (a ValueError; not a RecursionError,
    nor a deep object for every later recursive walk) when arrays and objects nest deeper than
    ``max_depth``."""
    depth = json_depth(text)
    if depth > max_depth:
        raise TooDeep(f"its arrays and objects nest {depth} deep (at most {max_depth})")
    try:
        return json.loads(text, **kwargs)
    except RecursionError:  # a second line: the scan above should have refused it
        raise TooDeep(f"its arrays and objects nest too deep (at most {max_depth})") from None


def parse_structured(text: str, schema: type[T]) -> T:
    """Validate ``text`` against ``schema``; a ValueError says why it failed, in words."""
    candidate = extract_json(text)
    try:
        data = loads_bounded(candidate, strict=False)  # tolerate raw newlines inside strings
    except json.JSONDecodeError as exc:
        raise ValueError(f"it is not valid JSON ({exc.msg} at character {exc.pos})") from exc
    try:
        return schema.model_validate(data)
    except ValidationError as exc:
        problems = "; ".join(
            f"{'.'.join(str(p) for p in err['loc']) or '(root)'}: {err['msg']}" for err in exc.errors()
        )
        raise ValueError(f"it does not match the schema ({problems})") from exc


class BackendModel(ChatModel):
    """A :class:`ChatModel` over a backend, with response cache, accounting and repair rounds.

    ``max_repairs``: after an answer that fails to parse, the model is told why ("your answer
    did not parse because …") and asked again, at most this many times.
    """

    def __init__(
        self,
        backend: Backend,
        *,
        cache: Any = None,  # ResponseCache | None (import kept lazy)
        usage: Usage | None = None,
        max_repairs: int = 2,
    ) -> None:
        self.backend = backend
        self.cache = cache
        self.usage = usage if usage is not None else Usage()
        self.max_repairs = max_repairs
        self.name = f"{backend.kind}:{backend.model_name}"
        self.accepts_images = backend.accepts_images

    def chat(
        self,
        messages: list[Message],
        *,
        temperature: float = 0.0,
        max_tokens: int = 512,
        prompt_version: str = "",
        seed: int | None = None,
    ) -> str:
        request = ChatRequest(
            messages=messages, temperature=temperature, max_tokens=max_tokens,
            seed=self.backend.seed if seed is None else seed,
        )
        return self._call(request, "chat", prompt_version).text

    def structured(
        self,
        messages: list[Message],
        schema: type[T],
        *,
        temperature: float = 0.0,
        max_tokens: int = 512,
        prompt_version: str = "",
        seed: int | None = None,
    ) -> T:
        json_schema = schema.model_json_schema()
        conversation = list(messages)
        reasons: list[str] = []
        for round_ in range(self.max_repairs + 1):
            request = ChatRequest(
                messages=conversation,
                temperature=temperature,
                max_tokens=max_tokens,
                seed=self.backend.seed if seed is None else seed,
                json_schema=json_schema,
                schema_name=schema.__name__,
            )
            completion = self._call(request, "structured", prompt_version)
            try:
                return parse_structured(completion.text, schema)
            except TooDeep as exc:  # hostile, not a slip to repair
                self.usage.record_error()
                raise AnswerTooDeepError(f"{self.name} answered JSON whose {exc}; not parsed") from None
            except ValueError as exc:
                reason = str(exc)
                if completion.finish_reason == "length":
                    reason += f"; the answer was cut off at max_tokens={max_tokens}"
                reasons.append(reason)
            if round_ < self.max_repairs:
                self.usage.record_repair()
                repair = prompt_template("structured_repair").format(
                    reason=reasons[-1], schema=json.dumps(json_schema, separators=(",", ":"))
                )
                conversation = [
                    *conversation,
                    Message(role="assistant", content=completion.text),
                    Message(role="user", content=repair),
                ]
        self.usage.record_error()
        raise StructuredOutputError(
            f"{self.name} gave no valid {schema.__name__} after {self.max_repairs + 1} tries: "
            + " | ".join(reasons)
        )

    def _call(self, request: ChatRequest, kind: str, prompt_version: str) -> Completion:
        if request.has_images and not self.accepts_images:
            self.usage.record_error()
            raise ImagesNotSupportedError(
                f"{self.name} is a text-only model and cannot look at images; "
                "use a vision model (e.g. --vlm openai:<vision-model>) for image messages"
            )
        started = time.perf_counter()
        key = None
        if self.cache is not None and self.cache.mode != "off":
            b = self.backend
            key = self.cache.key(b.kind, b.model_name, request, prompt_version, b.server)
            hit = self.cache.get(key)
            if hit is None and b.server is not None and getattr(self.cache, "legacy_keys", False):  # recorded before keys named servers
                hit = self.cache.get(self.cache.key(b.kind, b.model_name, request, prompt_version))
            if hit is not None:
                self.usage.record(self._record(kind, hit, started, cache_hit=True))
                return hit
            if self.cache.mode == "replay":
                self.usage.record_error()
                raise CacheMissError(self.cache.describe_miss(key, request))
        try:
            completion = self.backend.complete(request)
        except ModelError:
            self.usage.record_error()
            raise
        if key is not None:
            self.cache.put(key, completion, backend=self.backend.kind, model=self.backend.model_name)
        self.usage.record(self._record(kind, completion, started, cache_hit=False))
        return completion

    def _record(self, kind: str, c: Completion, started: float, *, cache_hit: bool) -> CallRecord:
        return CallRecord(
            backend=self.backend.kind,
            model=self.backend.model_name,
            kind=kind,
            prompt_tokens=0 if cache_hit else c.prompt_tokens,
            completion_tokens=0 if cache_hit else c.completion_tokens,
            latency_s=time.perf_counter() - started,
            cache_hit=cache_hit,
            attempts=1 if cache_hit else c.attempts,
        )

    def close(self) -> None:
        self.backend.close()
