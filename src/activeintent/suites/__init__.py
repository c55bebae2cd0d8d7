"""Benchmark suites of hidden intentions: ``paper`` (the paper's four), ``library`` (the other
built-in intentions), ``heldout`` (written blind, before any learner change, in
``suites/heldout.py``; reported separately), ``heldout2`` (a second held-out suite, ``h2-…``,
written blind with the world's helpers only, in ``suites/heldout2.py``; reported
separately, like ``heldout``), ``dev`` (``suites/dev.py``: for tuning learners) and
``truth-goals`` (``truth-00`` … ``truth-49``: 50 goals of the goal language drawn at random and
committed as data, ``suites/truth_goals.json``; learning efficiency apart from coverage).
Names of every suite resolve everywhere an intention name is accepted. Suites are the registry
:data:`SUITES`; a plug-in file adds its own (``SUITES.register("mine", Suite(load=...))``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from activeintent.intentions.base import Intention
from activeintent.intentions.registry import (
    INTENTION_NAMES,
    INTENTIONS,
    PAPER_INTENTIONS,
    IntentionError,
    get_intention,
    resolve_intention,
)
from activeintent.memo import memoized
from activeintent.registry import Registry, UnknownName
from activeintent.suites.dev import dev_intentions
from activeintent.suites.heldout import heldout_intentions
from activeintent.suites.heldout2 import heldout2_intentions
from activeintent.suites.truth_goals import truth_intentions


@dataclass(frozen=True)
class Suite:
    """A named set of hidden intentions. ``load`` makes them (name → Intention; imported on
    first use), ``held_out``: written blind, never tuned on, reported per intention only after
    a freeze (docs/results/HELDOUT_RUNS.md)."""

    load: Callable[[], dict[str, Intention]]
    held_out: bool = False


def _paper() -> dict[str, Intention]:
    return {n: get_intention(n) for n in PAPER_INTENTIONS}


def _library() -> dict[str, Intention]:
    return {n: get_intention(n) for n in INTENTION_NAMES if n not in PAPER_INTENTIONS}


def _heldout() -> dict[str, Intention]:
    return {it.name: it for it in heldout_intentions()}


def _heldout2() -> dict[str, Intention]:
    return {it.name: it for it in heldout2_intentions()}


def _dev() -> dict[str, Intention]:
    return {it.name: it for it in dev_intentions()}


def _truth() -> dict[str, Intention]:
    return {it.name: it for it in truth_intentions()}


# The suites, in the order they are listed and searched; a plug-in adds its own with
# SUITES.register("name", Suite(load=...)).
SUITES: Registry[Suite] = Registry("suite")
SUITES.register("paper", Suite(_paper), help="the paper's four intentions")
SUITES.register("library", Suite(_library), help="the other built-in intentions")
SUITES.register("heldout", Suite(_heldout, held_out=True), help="written blind before any learner change")
SUITES.register("heldout2", Suite(_heldout2, held_out=True), help="a second blind suite, the world's helpers only")
SUITES.register("dev", Suite(_dev), help="for developing learners")
SUITES.register("truth-goals", Suite(_truth), help="50 goals of the goal language drawn at random")

SUITE_NAMES = tuple(SUITES.names())  # the built-in ones
HELDOUT_SUITES = tuple(n for n in SUITE_NAMES if SUITES[n].held_out)  # written blind; never tuned on


def is_held_out(suite_name: str) -> bool:
    return suite_name in SUITES and SUITES[suite_name].held_out


@memoized(size=64, why="a suite's intention names by suite name: its loader reads files that do not change while the process runs")
def _names(suite_name: str) -> tuple[str, ...]:
    return tuple(SUITES[suite_name].load())


def suite(name: str) -> list[str]:
    """Intention names of a suite (unknown names list the valid ones)."""
    try:
        SUITES.check(name)
    except UnknownName as err:
        raise ValueError(str(err)) from None
    if name in ("paper", "library"):  # the intention registry can grow (plug-ins): not cached
        return list(SUITES[name].load())
    return list(_names(name))


def suite_of(intention: str) -> str:
    """The suite an intention name belongs to: 'file' for path.py:NAME, 'plugin' for one a
    plug-in file registered, 'other' for a name no suite holds."""
    if ".py:" in intention:
        return "file"
    if intention in PAPER_INTENTIONS:
        return "paper"
    if intention in INTENTION_NAMES:
        return "library"
    if intention in INTENTIONS:
        return "plugin"
    for name in SUITES:
        if name not in ("paper", "library") and intention in _names(name):
            return name
    return "other"


def resolve(name: str | None, intention_file: str | None = None) -> Intention:
    """``--intention NAME`` (any suite) or ``--intention-file path.py:NAME``."""
    if name and not intention_file and name not in INTENTIONS:
        for suite_name in SUITES:
            if suite_name not in ("paper", "library") and name in _names(suite_name):
                return SUITES[suite_name].load()[name]
        try:
            return get_intention(name)
        except IntentionError as err:
            others = "; ".join(f"{n}: {_listed(n)}" for n in SUITES if n not in ("paper", "library"))
            raise IntentionError(f"{err} Intentions of the other suites — {others}.") from None
    return resolve_intention(name, intention_file)


def _listed(suite_name: str) -> str:
    names = _names(suite_name)
    return ", ".join(names) if len(names) <= 20 else f"{names[0]} … {names[-1]} ({len(names)})"
