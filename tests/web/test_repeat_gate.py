"""Repeated log lines are held back to one per interval, and the next says how many were held:
the server's own rate-limited warnings and uvicorn's lines (QuietRepeats) share one gate."""

from __future__ import annotations

import logging

from activeintent.web.errors import RateLimitedLog, RepeatGate
from activeintent.web.transport import QuietRepeats


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_one_line_per_interval_and_the_next_counts_those_held_back():
    clock = Clock()
    gate = RepeatGate(every=10, clock=clock)
    assert gate.admit("a") == ""
    assert [gate.admit("a") for _ in range(3)] == [None] * 3
    assert gate.admit("b") == ""  # each kind has its own interval
    clock.now += 12
    assert gate.admit("a") == " (and 3 more like it in the last 12 s)"
    assert gate.admit("a") is None


def test_a_forgotten_kind_passes_again_and_keeps_its_count_without_a_time():
    clock = Clock()
    gate = RepeatGate(every=10, clock=clock, size=1)
    gate.admit("a")
    gate.admit("a")  # held
    gate.admit("b")  # "a" is forgotten: it would pass again at once
    assert gate.admit("a") == ""


def test_the_log_and_the_filter_add_the_note(caplog):
    clock = Clock()
    logger = logging.getLogger("test-repeat-gate")
    log = RateLimitedLog(logger, every=10, clock=clock)
    with caplog.at_level(logging.WARNING, logger="test-repeat-gate"):
        assert log.warning("bad", "bad request from %s", "x")
        assert not log.warning("bad", "bad request from %s", "y")
        clock.now += 20
        assert log.warning("bad", "bad request from %s", "z")
    assert [r.getMessage() for r in caplog.records] == [
        "bad request from x", "bad request from z (and 1 more like it in the last 20 s)"]
    quiet = QuietRepeats(every=10, clock=clock)
    record = logging.LogRecord("uvicorn", logging.WARNING, __file__, 1, "Invalid HTTP request", None, None)
    assert quiet.filter(record) and not quiet.filter(record)
    clock.now += 11
    assert quiet.filter(record) and record.getMessage() == "Invalid HTTP request (and 1 more like it in the last 11 s)"
