"""The models a run uses: which answer (:class:`ModelsConfig`, the spec's ``models`` section)
and the handles loaded for them (:class:`Models`)."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from activeintent.llm.embedded import EmbeddedConfig
from activeintent.llm.registry import load_model, parse_spec


class ModelsConfig(BaseModel):
    """Which models answer (specs as in docs/models.md) and how their replies are cached."""

    model_config = ConfigDict(extra="forbid")

    llm: str = Field("embedded", description="LLM: embedded | gguf:/path.gguf | openai:<model> | none (Bayesian methods "
                     "and baselines)")
    vlm: str | None = Field(None, description="Multimodal model spec for the retriever (default: the LLM)")
    base_url: str | None = Field(None, description="OpenAI-compatible endpoint",
                                 json_schema_extra={"envvar": "OPENAI_BASE_URL"})
    cache: str | None = Field(None, description="Response cache file (SQLite); default ~/.cache/activeintent")
    cache_mode: str = Field("record", pattern="^(record|replay|off)$", description="record | replay | off")



EXECUTOR_CTX = 8192  # the planner's prompts are ~750 tokens and its answers short


class Models:
    """The models a run uses, loaded on first use (Bayesian methods may need none)."""

    def __init__(self, config: ModelsConfig):
        for spec in (config.llm, config.vlm):
            if spec not in (None, "none"):
                parse_spec(spec)  # a typo in a model spec is refused before any work
        self.config = config
        self._loaded: dict[str, Any] = {}

    def _load(self, spec: str | None):
        if spec is None or spec == "none":
            return None
        if spec not in self._loaded:
            c = self.config
            self._loaded[spec] = load_model(spec, base_url=c.base_url, cache_path=c.cache, cache_mode=c.cache_mode)
        return self._loaded[spec]

    @property
    def llm(self):
        return self._load(self.config.llm)

    @property
    def vlm(self):
        return self._load(self.config.vlm)

    @property
    def executor_llm(self):
        """The LLM the executor plans with: the same model, but an in-process one gets its own
        KV cache (EXECUTOR_SLOT), so neither the learner's growing conversation nor the
        planner's fixed prompt evicts the other's prefix (the same answers: a kept prefix gives
        the logits of a fresh evaluation)."""
        spec = self.config.llm
        if spec is None or spec == "none" or not (spec == "embedded" or spec.startswith("gguf:")):
            return self.llm
        key = f"{spec}#executor"
        if key not in self._loaded:
            c = self.config
            self._loaded[key] = load_model(spec, base_url=c.base_url, cache_path=c.cache, cache_mode=c.cache_mode,
                                           embedded=EmbeddedConfig(kv_slot="executor", n_ctx=EXECUTOR_CTX))
        return self._loaded[key]

    def _totals(self):
        return [m.usage.snapshot() for m in self._loaded.values() if m is not None and m.usage is not None]

    def usage(self) -> tuple[int, int, int]:
        t = self._totals()
        return sum(x.calls for x in t), sum(x.prompt_tokens for x in t), sum(x.completion_tokens for x in t)

    def model_time(self) -> float:
        return float(sum(x.latency_s for x in self._totals()))
