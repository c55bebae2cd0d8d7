"""Model spec strings → models, and the options every command shares
(``--llm SPEC --vlm SPEC --base-url URL --cache PATH --cache-mode record|replay|off``)."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel

from activeintent.llm.accounting import Usage
from activeintent.llm.backend import BackendModel
from activeintent.llm.base import ChatModel
from activeintent.llm.cache import ResponseCache, check_mode
from activeintent.llm.embedded import EmbeddedBackend, EmbeddedConfig
from activeintent.llm.retry import RetryPolicy

VALID_SPECS = (
    "embedded  (the packaged Gemma 3 270M, in process)",
    "gguf:/path/model.gguf  (any GGUF file, in process)",
    "openai:<model-name>  (an OpenAI-compatible server; --base-url / OPENAI_BASE_URL)",
)


class ModelSpec(BaseModel):
    kind: Literal["embedded", "gguf", "openai"]
    target: str | None = None  # GGUF path or remote model name

    def __str__(self) -> str:
        return self.kind if self.target is None else f"{self.kind}:{self.target}"


def parse_spec(spec: str) -> ModelSpec:
    """``embedded`` | ``gguf:/path/model.gguf`` | ``openai:<model-name>``; else a ValueError
    that lists the valid forms."""
    text = (spec or "").strip()
    if text == "embedded":
        return ModelSpec(kind="embedded")
    kind, sep, target = text.partition(":")
    if sep and kind in ("gguf", "openai") and target.strip():
        return ModelSpec(kind=kind, target=target.strip())  # type: ignore[arg-type]
    raise ValueError(
        f"invalid model spec {spec!r}; valid forms:\n  " + "\n  ".join(VALID_SPECS)
    )


def load_model(
    spec: str,
    *,
    base_url: str | None = None,
    cache: ResponseCache | str | Path | None = None,
    cache_path: str | Path | None = None,
    cache_mode: str = "record",
    usage: Usage | None = None,
    embedded: EmbeddedConfig | None = None,
    retry: RetryPolicy | None = None,
    timeout_s: float = 120.0,
    max_repairs: int = 2,
    seed: int = 0,
) -> ChatModel:
    """Build the model named by ``spec``.

    ``cache`` is a :class:`ResponseCache`, or the cache file (also accepted as ``cache_path``;
    default ~/.cache/activeintent/responses.sqlite) opened in ``cache_mode``
    (record | replay | off).
    """
    parsed = parse_spec(spec)
    check_mode(cache_mode)
    if not isinstance(cache, ResponseCache):
        path = cache if cache is not None else cache_path
        cache = ResponseCache(path, cache_mode) if cache_mode != "off" else None
    if parsed.kind == "openai":
        import os

        # lazy: the openai SDK takes ~1.5 s to import; only remote models need it
        from activeintent.llm.openai_compat import DUMMY_API_KEY, OpenAIBackend

        # Replaying a recorded cache needs no server and so no key.
        offline = cache is not None and cache.mode == "replay" and not os.environ.get("OPENAI_API_KEY")
        backend = OpenAIBackend(
            parsed.target or "",
            base_url=base_url,
            api_key=DUMMY_API_KEY if offline else None,
            timeout_s=timeout_s,
            retry=retry or RetryPolicy(seed=seed),
            seed=seed,
        )
    else:
        config = embedded or EmbeddedConfig(seed=seed)
        backend = EmbeddedBackend(parsed.target if parsed.kind == "gguf" else None, config)
    return BackendModel(backend, cache=cache, usage=usage, max_repairs=max_repairs)
