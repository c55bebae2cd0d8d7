"""A test double: answers from a queue or a callback, and records every request it got.

It goes through the same layer as the real backends (:class:`BackendModel`), so structured
answers are still validated against the schema (an invalid scripted answer is a
StructuredOutputError, not a silently accepted object) and cache/accounting behave as for real.
"""

from __future__ import annotations

import json
from collections import deque
from collections.abc import Callable, Iterable
from typing import Any

from pydantic import BaseModel

from activeintent.llm.accounting import Usage
from activeintent.llm.backend import Backend, BackendModel, ChatRequest, Completion
from activeintent.llm.base import Message, ModelError

# An answer: text, a JSON-able dict, a pydantic object, or a callback computing one from the
# messages and the requested JSON schema (None for free text).
Answer = str | dict[str, Any] | BaseModel
Responder = Callable[[list[Message], dict[str, Any] | None], Answer]


def _as_text(answer: Answer) -> str:
    if isinstance(answer, BaseModel):
        return answer.model_dump_json()
    if isinstance(answer, dict):
        return json.dumps(answer)
    return str(answer)


class ScriptedBackend(Backend):
    kind = "scripted"

    def __init__(
        self,
        answers: Iterable[Answer | Responder] = (),
        *,
        respond: Responder | None = None,
        accepts_images: bool = True,
        model_name: str = "scripted",
    ) -> None:
        self.queue: deque[Answer | Responder] = deque(answers)
        self.respond = respond
        self.accepts_images = accepts_images
        self.model_name = model_name
        self.requests: list[ChatRequest] = []

    def complete(self, request: ChatRequest) -> Completion:
        self.requests.append(request)
        if self.queue:
            item = self.queue.popleft()
        elif self.respond is not None:
            item = self.respond
        else:
            raise ModelError(
                f"ScriptedModel ran out of answers after {len(self.requests) - 1} calls "
                f"(last user message: {_last_user_text(request.messages)[:200]!r})"
            )
        answer = item(request.messages, request.json_schema) if callable(item) else item
        text = _as_text(answer)
        prompt_words = sum(len(m.text.split()) for m in request.messages)
        return Completion(text=text, prompt_tokens=prompt_words, completion_tokens=len(text.split()))


def _last_user_text(messages: list[Message]) -> str:
    return next((m.text for m in reversed(messages) if m.role == "user"), "")


class ScriptedModel(BackendModel):
    """``ScriptedModel([answer, ...])`` or ``ScriptedModel(respond=fn)``; ``calls`` holds the
    requests (messages, json_schema) in order, ``last_prompt`` the last user text."""

    def __init__(
        self,
        answers: Iterable[Answer | Responder] = (),
        *,
        respond: Responder | None = None,
        accepts_images: bool = True,
        name: str = "scripted",
        cache: Any = None,
        usage: Usage | None = None,
        max_repairs: int = 0,
    ) -> None:
        backend = ScriptedBackend(
            answers, respond=respond, accepts_images=accepts_images, model_name=name
        )
        super().__init__(backend, cache=cache, usage=usage, max_repairs=max_repairs)
        self.scripted = backend

    @property
    def calls(self) -> list[ChatRequest]:
        return self.scripted.requests

    @property
    def last_prompt(self) -> str:
        if not self.calls:
            raise ModelError("ScriptedModel has not been called")
        return _last_user_text(self.calls[-1].messages)

    def push(self, *answers: Answer | Responder) -> None:
        self.scripted.queue.extend(answers)
