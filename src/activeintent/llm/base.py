"""The one interface every learner uses to talk to a (multimodal) chat model."""

from __future__ import annotations

import io
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Literal, TypeVar

import numpy as np
from pydantic import BaseModel

if TYPE_CHECKING:
    from activeintent.llm.accounting import Usage

T = TypeVar("T", bound=BaseModel)


class TextPart(BaseModel):
    type: Literal["text"] = "text"
    text: str


class ImagePart(BaseModel):
    """An image as PNG bytes (build one from an RGB array with :meth:`from_array`)."""

    type: Literal["image"] = "image"
    png: bytes

    @classmethod
    def from_array(cls, rgb: np.ndarray) -> ImagePart:
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(np.asarray(rgb, dtype=np.uint8)).save(buf, format="PNG")
        return cls(png=buf.getvalue())


class Message(BaseModel):
    role: Literal["system", "user", "assistant"]
    content: str | list[TextPart | ImagePart]

    @property
    def has_images(self) -> bool:
        return not isinstance(self.content, str) and any(isinstance(p, ImagePart) for p in self.content)

    @property
    def text(self) -> str:
        """The text parts joined (images left out)."""
        if isinstance(self.content, str):
            return self.content
        return "\n".join(p.text for p in self.content if isinstance(p, TextPart))


class ModelError(RuntimeError):
    """A model call failed for good (after retries), or the model cannot do what was asked."""


class TransientModelError(ModelError):
    """Timeouts, 429, 5xx, dropped connections or truncated bodies that outlasted every retry."""

    def __init__(self, message: str, *, attempts: int = 1) -> None:
        super().__init__(message)
        self.attempts = attempts


class ModelUnavailableError(ModelError):
    """The model cannot be reached or does not exist (no server, unknown model, bad key)."""


class ModelRedirectError(ModelError):
    """The server answered with a redirect. Not followed: the prompt would go to another server
    (``location`` says which), so the caller decides whether to point ``--base-url`` there."""

    def __init__(self, message: str, *, location: str = "") -> None:
        super().__init__(message)
        self.location = location


class StructuredOutputError(ModelError):
    """The model's answer did not parse/validate against the schema, even after repair rounds."""


class AnswerTooDeepError(ModelError):
    """The model's JSON nests deeper than any answer needs (``backend.MAX_JSON_DEPTH``): refused
    unparsed and not repaired, an error of the call rather than an unusable answer."""


class ContextOverflowError(ModelError):
    """The prompt and its answer do not fit the model's context window (``n_ctx`` tokens). A
    caller that holds a long history can shorten it and ask again."""


class ImagesNotSupportedError(ModelError):
    """Images were sent to a text-only model (never dropped silently)."""


class CacheMissError(ModelError):
    """Replay mode: the response cache holds no answer for this request."""


class ChatModel(ABC):
    """A chat model: messages (text and images) in, text out.

    ``structured`` returns a validated pydantic object of ``schema``. ``prompt_version`` names
    the prompt template that built the messages; it is part of the response-cache key.
    ``usage`` (when set) accumulates tokens, latency and cache hits of every call.
    """

    name: str = "model"
    accepts_images: bool = False
    usage: Usage | None = None

    @abstractmethod
    def chat(
        self,
        messages: list[Message],
        *,
        temperature: float = 0.0,
        max_tokens: int = 512,
        prompt_version: str = "",
        seed: int | None = None,
    ) -> str:
        """Free-text completion. ``seed`` (default: the backend's) picks the draw when sampling
        at temperature > 0; it is part of the request, so of the cache key."""

    @abstractmethod
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
        """A validated instance of ``schema`` (repaired or raised as ModelError, never malformed)."""

    def close(self) -> None:  # noqa: B027 - optional hook, most models hold nothing
        """Free clients/connections held by the model."""
