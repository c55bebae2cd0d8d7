"""Progress for a log. When stdout is not a terminal (``... | cat``, CI, a nohup log) a rich
live display shows nothing until the end, so commands print one flushed line per step instead."""

from __future__ import annotations

import time
from collections.abc import Callable


def clock(seconds: float) -> str:
    """12 s → ``0:12``; 3725 s → ``1:02:05``."""
    s = int(round(max(seconds, 0.0)))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class Eta:
    """Elapsed time and the time left, from the steps finished since this clock started (steps
    done before it, e.g. episodes a resumed bench skips, took no time here)."""

    def __init__(self, total: int, done_before: int = 0, now: Callable[[], float] = time.monotonic):
        self.total, self.done_before, self.now = total, done_before, now
        self.start = now()

    def elapsed(self) -> float:
        return self.now() - self.start

    def text(self, done: int) -> str:
        """``elapsed 0:12 · ETA 0:30`` (``ETA ?`` before the first step here finished)."""
        elapsed = self.elapsed()
        here = done - self.done_before
        left = "?" if here <= 0 else clock(elapsed / here * (self.total - done))
        return f"elapsed {clock(elapsed)} · ETA {left}"


def print_line(console, text: str) -> None:
    """One line, never wrapped or highlighted, flushed at once so a log shows it now."""
    console.print(text, soft_wrap=True, highlight=False)
    console.file.flush()
