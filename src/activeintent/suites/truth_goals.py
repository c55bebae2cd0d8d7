"""The truth-goal suite (``--suite truth-goals``): 50 hidden intentions that are goals of the
goal language itself (``goals/language.py``), so the ``lang-*`` learners can represent
every one of them exactly. It measures learning efficiency alone, how quickly a learner finds a
goal it can express, apart from coverage (what the blind held-out suite measures).

The goals are drawn, not written: :func:`draw` with the committed seed, **uniformly over the
language's structure**, not by its description-length prior:

- the number of clauses is uniform in 1..``CLAUSE_CAP`` (``min(3, MAX_CLAUSES)``: 3 with
  today's language);
- each clause is an ``Each`` or a ``Form`` with probability 1/2; then every slot of the
  production (``Each``: quantifier, selector, relation; ``Form``: structure, selector) is a
  uniform choice among the node types of that slot, then a uniform choice among that node's
  parameters. Node types and parameters are taken in the order of their keys, so the draw
  depends only on the language's keys, which :func:`language_version` hashes;
- the "every other block stays where it is" flag is uniform.

A goal's clauses are put in key order (their order says nothing), and a stays flag that can
change nothing (on every sample scene the clauses' groups hold every block, e.g. a ``Form`` over
``all:``) is cleared, so that the same goal is not kept twice under two keys. A goal naming one
clause twice is dropped (it is a shorter goal written longer), and so is a key drawn before. A
goal is kept only if, on ``SCENES`` = 100 scenes of the protocol's public test-scene distribution
(``protocol.draw_test_scenes(SCENE_SEED, 100)``, the distribution every episode is scored on):

1. it can be shown: ``GoalIntention.feasible`` (static checks and the planner) holds on at
   least ``MIN_FEASIBLE`` = 20 % of them; and
2. it is not trivially satisfied: doing nothing (the scene's initial layout, with the layout
   seed the protocol draws with it) already satisfies it on fewer than ``MAX_ALREADY`` = 80 %
   of the scenes it is feasible on. A goal that the initial layout nearly always satisfies
   cannot be learned from demonstrations (a plan that does nothing is right anyway); and
3. it meets the protocol's promise for every suite (docs/protocol.md, item 4;
   ``tests/test_protocol.py``): it is feasible in at least ``MIN_SCORED`` = 5 of the 70 scenes
   scored at k = K in each of the ``DEFAULT_TRIALS`` = 20 trials a default bench runs. Filter 1
   estimates the rate on 100 scenes; a goal near 20 % can still fall short in one trial's pool.

The result is committed as data, ``truth_goals.json`` next to this module: the language
version, the seed, the filter settings, the draw's counts and the 50 goal keys with their
sentences. A change of the language changes its version and a test then fails until the suite
is redrawn::

    python -m activeintent.suites.truth_goals --redraw   # rewrites truth_goals.json
    python -m activeintent.suites.truth_goals --check    # redraws in memory, compares

Names are neutral (``truth-00`` … ``truth-49``); each intention's description is its goal's
sentence.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from activeintent.goals.facts import facts
from activeintent.goals.goal import MAX_CLAUSES, QUANTS, Each, Form, Goal, all_clauses, parse_goal
from activeintent.goals.nodes import nodes, speaking
from activeintent.learners.lang.hypotheses import GoalIntention
from activeintent.memo import memoized
from activeintent.protocol import (
    DEFAULT_TEST_POOL,
    DEFAULT_TEST_SCENES,
    draw_test_scenes,
    trial_seeds,
)
from activeintent.spec import EpisodeSeeds
from activeintent.world import Scene, WorldState, layout

PATH = Path(__file__).with_name("truth_goals.json")
SEED = 25  # issue 25
COUNT = 50
CLAUSE_CAP = min(3, MAX_CLAUSES)
SCENES = 100
SCENE_SEED = 2025
MIN_FEASIBLE = 0.2  # share of the scenes the goal can be shown on, at least
MAX_ALREADY = 0.8  # share of its feasible scenes whose initial layout already satisfies it, below
MIN_SCORED = 5  # feasible scenes in every default trial's pool, at least (bench.report.MIN_SCORED)
DEFAULT_TRIALS = 20  # trials of a default bench (bench --trials)
NAME_PREFIX = "truth-"
REDRAW = "python -m activeintent.suites.truth_goals --redraw"


LANGUAGE = 1  # the goal language's version the suite is drawn from (goals/language.py LANGUAGES)


def language_version() -> str:
    """A hash of the definition of language :data:`LANGUAGE`: every clause key, MAX_CLAUSES and
    QUANTS (changes when a node type, a parameter, a quantifier or the clause limit of that
    version changes)."""
    with speaking(LANGUAGE):
        text = json.dumps({"clauses": sorted(c.key for c in all_clauses()), "max_clauses": MAX_CLAUSES,
                           "quants": list(QUANTS)})
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def settings(seed: int = SEED) -> dict:
    """What the draw depends on besides the language (written into the file)."""
    return {"seed": seed, "count": COUNT, "filters": {
        "clause_cap": CLAUSE_CAP, "scenes": SCENES, "scene_seed": SCENE_SEED,
        "min_feasible": MIN_FEASIBLE, "max_already": MAX_ALREADY,
        "min_scored": MIN_SCORED, "default_trials": DEFAULT_TRIALS}}


# ---- the uniform draw over the language's structure ------------------------------------------


def _pick(rng: np.random.Generator, options) -> str:
    options = sorted(options)
    return options[int(rng.integers(len(options)))]


def _node(rng: np.random.Generator, kind: str) -> tuple[str, str]:
    key = _pick(rng, nodes(kind, LANGUAGE))
    return key, _pick(rng, nodes(kind, LANGUAGE)[key].params)


def random_clause(rng: np.random.Generator) -> Each | Form:
    if rng.random() < 0.5:
        quant = _pick(rng, QUANTS)
        sel, sp = _node(rng, "selector")
        rel, rp = _node(rng, "relation")
        return Each(quant, sel, sp, rel, rp)
    struct, stp = _node(rng, "structure")
    sel, sp = _node(rng, "selector")
    return Form(struct, stp, sel, sp)


def random_goal(rng: np.random.Generator) -> Goal:
    """One goal, uniformly over the structure (clauses in key order; may repeat a clause)."""
    n = int(rng.integers(1, CLAUSE_CAP + 1))
    clauses = sorted((random_clause(rng) for _ in range(n)), key=lambda c: c.key)
    return Goal(tuple(clauses), stays=bool(rng.random() < 0.5))


# ---- the filter ------------------------------------------------------------------------------


@memoized(size=2, why="a pure function of (seed, n): the protocol's scene draws and layouts")
def scene_sample(seed: int = SCENE_SEED, n: int = SCENES) -> tuple[tuple[Scene, WorldState], ...]:
    """The fixed sample of the protocol's test scenes, each with its initial state."""
    return tuple((scene, WorldState(positions=layout(scene, lseed))) for scene, lseed in draw_test_scenes(seed, n))


@memoized(size=1, why="no arguments: a pure function of the protocol's seeds and defaults")
def default_pools() -> tuple[tuple[Scene, ...], ...]:
    """The scenes scored at k = K in each trial of a default bench (bench seed 0): the test
    seed depends on the trial only, not on the intention."""
    out = []
    for trial in range(DEFAULT_TRIALS):
        _, test_seed = trial_seeds(0, "any intention", trial)
        seed = EpisodeSeeds.from_seed(0, test_seed).test
        out.append(tuple(s for s, _ in draw_test_scenes(seed, DEFAULT_TEST_SCENES + DEFAULT_TEST_POOL)))
    return tuple(out)


def fewest_scored(goal: Goal, stop_below: int | None = None) -> int:
    """The fewest scenes of one default trial's pool the goal is feasible in (with
    ``stop_below``: returns as soon as a pool has fewer)."""
    it = GoalIntention(goal)
    fewest = None
    for pool in default_pools():
        n = sum(bool(it.feasible(s)) for s in pool)
        fewest = n if fewest is None else min(fewest, n)
        if stop_below is not None and fewest < stop_below:
            break
    return int(fewest or 0)


def stays_is_vacuous(goal: Goal) -> bool:
    """On every sample scene, the union of the clauses' groups is every block (a group depends on
    the scene's objects only), so "every other block stays where it is" says nothing."""
    for scene, _ in scene_sample():
        if {b for c in goal.clauses for b in c.group(scene.blocks, scene.bowls)} != set(scene.blocks):
            return False
    return True


def measure(goal: Goal, stop_below: float | None = None) -> tuple[float, float]:
    """(share of the sample the goal is feasible on, share of those whose initial layout already
    satisfies it). With ``stop_below``, returns early (feasible share as far as known, 0.0) once
    the feasible share can no longer reach it."""
    sample = scene_sample()
    it = GoalIntention(goal)
    possible = [i for i, (scene, _) in enumerate(sample) if goal.possible(tuple(scene.objects))]
    need = None if stop_below is None else stop_below * len(sample)
    feasible: list[int] = []
    for n, i in enumerate(possible):
        if need is not None and len(feasible) + len(possible) - n < need - 1e-9:
            return len(feasible) / len(sample), 0.0
        if it.feasible(sample[i][0]):
            feasible.append(i)
    already = sum(goal.holds(facts(sample[i][1])) for i in feasible)
    return len(feasible) / len(sample), (already / len(feasible) if feasible else 0.0)


def _clause_count() -> int:
    with speaking(LANGUAGE):
        return len(all_clauses())


def draw(seed: int = SEED, count: int = COUNT) -> dict:
    """The suite drawn from ``seed``: the contents of ``truth_goals.json``."""
    rng = np.random.default_rng(seed)
    seen: set[str] = set()
    kept: list[dict] = []
    why: Counter[str] = Counter()
    candidates = cleared = 0
    while len(kept) < count:
        goal = random_goal(rng)
        candidates += 1
        if goal.stays and stays_is_vacuous(goal):
            goal = Goal(goal.clauses, stays=False)
            cleared += 1
        keys = [c.key for c in goal.clauses]
        if len(set(keys)) < len(keys):
            why["repeats a clause"] += 1
            continue
        if goal.key in seen:
            why["duplicate key"] += 1
            continue
        seen.add(goal.key)
        feasible, already = measure(goal, stop_below=MIN_FEASIBLE)
        if feasible < MIN_FEASIBLE - 1e-9:
            why[f"feasible on < {MIN_FEASIBLE:.0%} of the scenes"] += 1
            continue
        if already >= MAX_ALREADY - 1e-9:
            why[f"already satisfied on >= {MAX_ALREADY:.0%} of its feasible scenes"] += 1
            continue
        scored = fewest_scored(goal, stop_below=MIN_SCORED)
        if scored < MIN_SCORED:
            why[f"feasible in < {MIN_SCORED} scenes of a default trial's pool"] += 1
            continue
        kept.append({"name": f"{NAME_PREFIX}{len(kept):02d}", "key": goal.key, "sentence": goal.sentence(),
                     "clauses": len(goal.clauses), "feasible": round(feasible, 4), "already": round(already, 4), "fewest_scored": scored})
    return {
        "about": "The truth-goal suite (--suite truth-goals), drawn by activeintent.suites.truth_goals; "
                 f"do not edit by hand: redraw with `{REDRAW}`.",
        "language_version": language_version(),
        "language": {"clauses": _clause_count(), "max_clauses": MAX_CLAUSES, "quants": list(QUANTS)},
        **settings(seed),
        "draw": {"candidates": candidates, "kept": len(kept),
                 "stays_cleared": cleared, "rejected": dict(sorted(why.items()))},
        "goals": kept,
    }


# ---- the committed suite ---------------------------------------------------------------------


@memoized(size=1, why="the committed truth_goals.json: wrong only if the file changes while the process runs")
def committed() -> dict:
    """The committed ``truth_goals.json``."""
    return json.loads(PATH.read_text())


def truth_names() -> list[str]:
    return [g["name"] for g in committed()["goals"]]


def truth_intentions() -> list[GoalIntention]:
    """A fresh GoalIntention per committed goal, in the suite's order."""
    out = []
    for g in committed()["goals"]:
        it = GoalIntention(parse_goal(g["key"]), name=g["name"])
        it.description = g["sentence"]
        out.append(it)
    return out


class TruthTracker:
    """Episode observer (evaluation side only): −log₂ of the belief the learner holds on the
    hidden goal itself, at k = 0 and after every answer, into ``diagnostics.truth_bits`` (None
    where the learner does not hold the goal's key). The learner is read, never told."""

    def __init__(self, learner, goal: Goal):
        self.learner, self.key, self.bits = learner, goal.key, []

    def _read(self) -> None:
        p = self.learner.mass_of(self.key)
        self.bits.append(None if not p else round(-float(np.log2(p)), 4))

    def started(self, episode) -> None:
        self._read()

    def answered(self, log) -> None:
        self._read()

    def finished(self, result) -> None:
        result.diagnostics["truth_bits"] = self.bits


def truth_tracker(learner, intention) -> TruthTracker | None:
    """A tracker when the hidden intention is a goal and the learner can say its mass on one."""
    goal = getattr(intention, "goal", None)
    return TruthTracker(learner, goal) if isinstance(goal, Goal) and hasattr(learner, "mass_of") else None


def write(data: dict, path: Path = PATH) -> None:
    path.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m activeintent.suites.truth_goals", description=__doc__.split("\n\n")[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--redraw", action="store_true", help=f"redraw and rewrite {PATH.name}")
    group.add_argument("--check", action="store_true", help=f"redraw in memory and compare with {PATH.name}")
    parser.add_argument("--seed", type=int, default=None, help="seed of the draw (default: the committed one)")
    args = parser.parse_args(argv)
    seed = args.seed if args.seed is not None else (committed()["seed"] if PATH.exists() else SEED)
    data = draw(seed)
    if args.redraw:
        write(data)
        print(f"wrote {PATH}: {len(data['goals'])} goals, language {data['language_version']}, "
              f"{data['draw']['candidates']} candidates drawn")
        return 0
    same = data == committed()
    print(f"{PATH.name} {'matches' if same else 'differs from'} the redraw with seed {seed}")
    if not same:
        print(f"redraw with `{REDRAW}` and commit {PATH.name}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
