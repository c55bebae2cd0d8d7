"""Exponential backoff with jitter for transient model failures."""

from __future__ import annotations

import random
import time
from collections.abc import Callable
from typing import TypeVar

from pydantic import BaseModel, Field

R = TypeVar("R")


class Transient(Exception):
    """Raised by a backend attempt that may succeed when tried again."""

    def __init__(self, message: str, *, unreachable: bool = False, final: bool = False,
                 retry_after: float | None = None) -> None:
        super().__init__(message)
        self.unreachable = unreachable  # nothing answered at all (connection refused)
        self.final = final  # no use trying again (the call's deadline has passed)
        self.retry_after = retry_after  # seconds the server asked us to wait (Retry-After)


class RetryPolicy(BaseModel):
    """``max_attempts`` tries; the wait before try k+1 is
    ``min(max_delay_s, base_delay_s * 2**k)`` scaled by a factor in [1 - jitter, 1]."""

    max_attempts: int = Field(default=4, ge=1)
    base_delay_s: float = Field(default=0.5, ge=0)
    max_delay_s: float = Field(default=8.0, ge=0)
    jitter: float = Field(default=0.5, ge=0, le=1)
    seed: int = 0  # the jitter RNG's seed: runs are reproducible in their waits too

    def delays(self) -> list[float]:
        rng = random.Random(self.seed)
        out = []
        for k in range(self.max_attempts - 1):
            delay = min(self.max_delay_s, self.base_delay_s * 2**k)
            out.append(delay * (1.0 - self.jitter * rng.random()))
        return out


class RetryOutcome(BaseModel):
    attempts: int
    errors: list[str]
    unreachable: bool
    deadline_passed: bool = False  # stopped early: no time left for another attempt


def run_with_retry(
    attempt: Callable[[], R],
    policy: RetryPolicy,
    *,
    sleep: Callable[[float], None] = time.sleep,
    deadline: float | None = None,
    clock: Callable[[], float] = time.monotonic,
) -> tuple[R, int] | RetryOutcome:
    """Call ``attempt`` until it returns or raises something other than :class:`Transient`.

    A server's Retry-After is honoured when it is no longer than ``policy.max_delay_s`` and
    fits before ``deadline`` (a ``clock`` time), else ignored; either way the error text says so.
    No wait or attempt starts past ``deadline``.

    Returns ``(result, attempts)`` or, when every attempt was transient, a :class:`RetryOutcome`
    for the caller to turn into its typed error.
    """
    delays = policy.delays()
    errors: list[str] = []
    unreachable = True
    for k in range(policy.max_attempts):
        try:
            return attempt(), k + 1
        except Transient as exc:
            message = str(exc)
            unreachable = unreachable and exc.unreachable
            if exc.final or k == len(delays):
                errors.append(message)
                return RetryOutcome(attempts=k + 1, errors=errors, unreachable=unreachable, deadline_passed=exc.final)
            delay = delays[k]
            left = None if deadline is None else deadline - clock()
            if exc.retry_after is not None:
                wanted = exc.retry_after
                if wanted > policy.max_delay_s:
                    message += f" (Retry-After {wanted:g} s ignored: longer than the {policy.max_delay_s:g} s longest wait)"
                elif left is not None and wanted >= left:
                    message += f" (Retry-After {wanted:g} s ignored: past the call's deadline)"
                else:
                    delay = max(delay, wanted)
                    message += f" (Retry-After {wanted:g} s honoured)"
            errors.append(message)
            if left is not None and delay >= left:
                return RetryOutcome(attempts=k + 1, errors=errors, unreachable=unreachable, deadline_passed=True)
            sleep(delay)
    raise AssertionError("unreachable: the last attempt returns above")
