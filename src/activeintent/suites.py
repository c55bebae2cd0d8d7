"""Benchmark suites of hidden intentions: ``paper`` (the paper's four), ``library`` (the other
built-in intentions), ``heldout`` (written blind, before any learner change, in
``intentions/suites/heldout.py``; reported separately), ``heldout2`` (a second held-out suite, ``h2-…``,
written blind with the world's helpers only, in ``intentions/suites/heldout2.py``; reported
separately, like ``heldout``), ``dev`` (``intentions/suites/dev.py``: for tuning learners) and
``truth-goals`` (``truth-00`` … ``truth-49``: 50 goals of the goal language drawn at random and
committed as data, ``bench/truth_goals.json``; learning efficiency apart from coverage).
Names of every suite resolve everywhere an intention name is accepted.
"""

from __future__ import annotations

import functools

from activeintent.intentions.base import Intention
from activeintent.intentions.registry import (
    INTENTION_NAMES,
    INTENTIONS,
    PAPER_INTENTIONS,
    IntentionError,
    get_intention,
    resolve_intention,
)

SUITE_NAMES = ("paper", "library", "heldout", "heldout2", "dev", "truth-goals")
HELDOUT_SUITES = ("heldout", "heldout2")  # written blind; never tuned on; per intention only after a freeze


def _heldout() -> dict[str, Intention]:
    from activeintent.intentions.suites.heldout import heldout_intentions

    return {it.name: it for it in heldout_intentions()}


def _heldout2() -> dict[str, Intention]:
    from activeintent.intentions.suites.heldout2 import heldout2_intentions

    return {it.name: it for it in heldout2_intentions()}


@functools.cache
def _heldout2_names() -> frozenset[str]:
    return frozenset(_heldout2())


def _dev() -> dict[str, Intention]:
    from activeintent.intentions.suites.dev import dev_intentions

    return {it.name: it for it in dev_intentions()}


def _truth() -> dict[str, Intention]:
    from activeintent.bench.truth_goals import truth_intentions

    return {it.name: it for it in truth_intentions()}


def _truth_names() -> list[str]:
    from activeintent.bench.truth_goals import truth_names

    return truth_names()


def suite(name: str) -> list[str]:
    """Intention names of a suite."""
    if name == "paper":
        return list(PAPER_INTENTIONS)
    if name == "library":
        return [n for n in INTENTION_NAMES if n not in PAPER_INTENTIONS]
    if name == "heldout":
        return list(_heldout())
    if name == "heldout2":
        return list(_heldout2())
    if name == "dev":
        return list(_dev())
    if name == "truth-goals":
        return _truth_names()
    raise ValueError(f"Unknown suite {name!r}; valid suites: {', '.join(SUITE_NAMES)}.")


def suite_of(intention: str) -> str:
    """The suite an intention name belongs to ('file' for path.py:NAME)."""
    if ".py:" in intention:
        return "file"
    if intention in PAPER_INTENTIONS:
        return "paper"
    if intention in INTENTION_NAMES:
        return "library"
    if intention in INTENTIONS:  # registered by a plug-in file
        return "plugin"
    if intention.startswith("truth-") and intention in _truth_names():
        return "truth-goals"
    if intention in _heldout2_names():
        return "heldout2"
    return "dev" if intention in _dev() else "heldout"


def resolve(name: str | None, intention_file: str | None = None) -> Intention:
    """``--intention NAME`` (any suite) or ``--intention-file path.py:NAME``."""
    if name and not intention_file and name not in INTENTIONS:
        dev = _dev()
        if name in dev:
            return dev[name]
        held = _heldout()
        if name in held:
            return held[name]
        held2 = _heldout2()
        if name in held2:
            return held2[name]
        truth = _truth()
        if name in truth:
            return truth[name]
        try:
            return get_intention(name)
        except IntentionError as err:
            raise IntentionError(
                f"{err} Held-out intentions: {', '.join(held)}. Held-out-2 intentions: "
                f"{', '.join(held2)}. Dev intentions: {', '.join(dev)}. "
                f"Truth-goal intentions: {_truth_names()[0]} … {_truth_names()[-1]}."
            ) from None
    return resolve_intention(name, intention_file)
