"""Token, latency and cache accounting of model calls (per call logged, totals per episode)."""

from __future__ import annotations

import logging
import threading

from pydantic import BaseModel

log = logging.getLogger("activeintent.llm")


class CallRecord(BaseModel):
    """One model call as seen by the caller (a cache hit is a call that reached no model)."""

    backend: str
    model: str
    kind: str  # "chat" or "structured"
    prompt_tokens: int = 0
    completion_tokens: int = 0
    latency_s: float = 0.0
    cache_hit: bool = False
    attempts: int = 1  # HTTP/backend attempts, > 1 when transient failures were retried


class UsageTotals(BaseModel):
    """A frozen view of :class:`Usage`; ``b - a`` is what happened between two snapshots."""

    calls: int = 0
    cache_hits: int = 0
    cache_misses: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    latency_s: float = 0.0
    retries: int = 0
    repairs: int = 0
    errors: int = 0

    def __sub__(self, other: UsageTotals) -> UsageTotals:
        return UsageTotals(
            **{name: getattr(self, name) - getattr(other, name) for name in UsageTotals.model_fields}
        )

    def __add__(self, other: UsageTotals) -> UsageTotals:
        return UsageTotals(
            **{name: getattr(self, name) + getattr(other, name) for name in UsageTotals.model_fields}
        )


class Usage:
    """Running totals shared by the models of one run (thread-safe).

    ``start = usage.snapshot(); ...episode...; usage.diff(start)`` gives per-episode totals.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._totals = UsageTotals()

    def record(self, call: CallRecord) -> None:
        with self._lock:
            t = self._totals
            t.calls += 1
            t.cache_hits += int(call.cache_hit)
            t.cache_misses += int(not call.cache_hit)
            t.prompt_tokens += call.prompt_tokens
            t.completion_tokens += call.completion_tokens
            t.latency_s += call.latency_s
            t.retries += call.attempts - 1
        log.info(
            "%s call %s/%s: %d+%d tokens, %.3fs, %s%s",
            call.kind,
            call.backend,
            call.model,
            call.prompt_tokens,
            call.completion_tokens,
            call.latency_s,
            "cache hit" if call.cache_hit else "cache miss",
            f", {call.attempts} attempts" if call.attempts > 1 else "",
        )

    def record_repair(self) -> None:
        with self._lock:
            self._totals.repairs += 1

    def record_error(self) -> None:
        with self._lock:
            self._totals.errors += 1

    def snapshot(self) -> UsageTotals:
        with self._lock:
            return self._totals.model_copy()

    def diff(self, since: UsageTotals) -> UsageTotals:
        return self.snapshot() - since
