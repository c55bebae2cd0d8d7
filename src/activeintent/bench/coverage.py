"""Coverage: how well the goal language can say what an intention means (``activeintent coverage``).

For one hidden intention, the best goal z* of the language *by behaviour*: the goal whose own
plan, executed from a scene's layout, satisfies the intention on the largest share of the
benchmark's test scenes in which the intention is feasible. That share, measured on a separate
set of scenes, is the **oracle**: the ceiling of any learner of this language (a learner whose
whole belief sits on z* scores it; nothing scores more, short of luck).

This is an evaluator: it reads the hidden intention (its checker, its feasibility, its oracle
plan), which no learner may. The search, for each intention:

1. *Selection scenes*: ``scenes`` test scenes (the protocol's test-scene distribution, seeded,
   kept when the intention is feasible), each with a bank of labelled states: the layout, the
   steps of the intention's own plan, random moves away from its final state, random walks
   from the layout. The label of a state is ``intention.satisfied``.
2. *Cheap filter*: every clause of the language is judged on every state (one numpy pass per
   state). One-clause goals and pairs of clauses (the pairs' clauses drawn from those that hold
   on most of the intention's satisfied states) are ranked by balanced agreement with the
   labels; a goal that cannot be shown in a scene counts as not holding there.
3. *Plans*: the ``top`` best-ranked goals, each with and without "every other block stays
   where it is", are planned on every selection scene; their plan success is measured and the
   final states of their plans join the bank (labelled), so goals whose plans go wrong lose
   rank in the next ``rounds``.
4. The goal with the largest plan success on the selection scenes (fewest bits on a tie) is
   z*; its plan success on ``test_scenes`` further scenes (another seed) is reported.

The search covers one- and two-clause goals (with and without "stays"); the learner's own
starting space is the ``KEEP`` shortest behaviourally distinct ones, so the report also says
whether z* is in it, its description length L(z*) and its prior rank.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from activeintent.goals.facts import facts
from activeintent.goals.goal import Goal, all_clauses, parse_goal
from activeintent.goals.nodes import spoken
from activeintent.goals.planner import generic_moves, plan
from activeintent.goals.prior import FittedPrior, goal_bits, load_prior
from activeintent.intentions.base import Intention
from activeintent.learners.lang.learner import KEEP
from activeintent.learners.lang.space import Compiled, cache_path, cached_json, space_info
from activeintent.protocol import sample_test_scene, stable_seed
from activeintent.suites import is_held_out
from activeintent.world import Scene, WorldState, apply_skill, layout

SELECTION_SCENES = 30
TEST_SCENES = 100
TOP = 24  # goals planned per round (each with and without "stays")
ROUNDS = 3
PAIR_CLAUSES = 400  # clauses that may form pairs: the ones holding on most satisfied states
EXPRESSIBLE = 0.8  # oracle plan success below this: "not expressible"


@dataclass
class Trial:
    """One scene of the search: its layout state and the bank of labelled states."""

    scene: Scene
    start: WorldState
    states: list = field(default_factory=list)  # (Facts, satisfied)


@dataclass
class Coverage:
    """The best goal of the language for one intention."""

    intention: str
    description: str
    goal: str  # key of z*
    sentence: str
    bits: float
    prior_rank: int  # 1 + distinct goals of the enumerated language with fewer bits
    in_start_space: bool
    selection_success: float
    success: float  # on the test scenes: the oracle
    test_scenes: int
    planned_goals: int
    runner_up: list[dict]

    def row(self) -> dict:
        return self.__dict__.copy()


def feasible_scenes(intention: Intention, n: int, seed: int, purpose: str) -> list[tuple[Scene, int]]:
    """``n`` test scenes (with layout seeds) in which the intention is feasible, drawn from the
    protocol's test-scene distribution with a seed of their own."""
    rng = np.random.default_rng(stable_seed("coverage", purpose, seed))
    out: list[tuple[Scene, int]] = []
    for _ in range(200 * n):
        scene, layout_seed = sample_test_scene(rng), int(rng.integers(2**31))
        if intention.feasible(scene):
            out.append((scene, layout_seed))
            if len(out) == n:
                return out
    raise ValueError(f"{intention.name}: fewer than {n} feasible scenes in {200 * n} test scenes")


def run_plan(state: WorldState, steps) -> WorldState:
    for step in steps:
        state, _ = apply_skill(state, step)
    return state


def goal_success(goal: Goal, scenes: list[tuple[Scene, int]], intention: Intention,
                 starts: list[WorldState] | None = None) -> tuple[float, list[WorldState]]:
    """Share of ``scenes`` where z's plan (variant 0, as the learner executes it) ends in a state
    that satisfies the intention; also the final states (for the bank)."""
    hits, finals = 0, []
    for k, (scene, seed) in enumerate(scenes):
        s0 = starts[k] if starts else WorldState(positions=layout(scene, seed))
        if not goal.possible(tuple(scene.objects)):
            continue
        p = plan(goal, s0)
        if p is None:
            continue
        end = run_plan(s0, p)
        finals.append((k, end))
        hits += bool(intention.satisfied(end))
    return hits / max(len(scenes), 1), finals


def agreement(goal: Goal, intention: Intention, n: int = TEST_SCENES, seed: int = 0) -> dict:
    """A given goal against a checker, both ways, on ``n`` test scenes where the checker is
    feasible: the share where the goal's plan satisfies the checker, and the share where the
    checker's own plan satisfies the goal (a goal or checker with no plan there fails)."""
    scenes = feasible_scenes(intention, n, seed, "agreement")
    forward, _ = goal_success(goal, scenes, intention)
    backward = plan_satisfies(intention, lambda state: goal.holds(facts(state)), scenes)
    return {"goal": goal.key, "intention": intention.name, "scenes": len(scenes),
            "goal_plan_satisfies_checker": round(forward, 4), "checker_plan_satisfies_goal": round(backward, 4)}


def plan_satisfies(planner: Intention, satisfied: Callable[[WorldState], bool], scenes: list[tuple[Scene, int]]) -> float:
    """The share of ``scenes`` (laid out by their seeds) where ``planner``'s own plan, executed,
    ends in a state that ``satisfied`` accepts (no plan: a miss)."""
    hits = 0
    for scene, layout_seed in scenes:
        s0 = WorldState(positions=layout(scene, layout_seed))
        steps = planner.plan(s0)
        hits += steps is not None and bool(satisfied(run_plan(s0, steps)))
    return hits / max(len(scenes), 1)


def _bank(intention: Intention, scenes: list[tuple[Scene, int]], rng: np.random.Generator) -> list[Trial]:
    trials = []
    for scene, seed in scenes:
        s0 = WorldState(positions=layout(scene, seed))
        t = Trial(scene, s0)
        t.states.append(s0)
        steps = intention.plan(s0) or []
        s = s0
        for step in steps:
            s, _ = apply_skill(s, step)
            t.states.append(s)
        final = s
        for start, n_walks, length in ((final, 6, 1), (s0, 3, 3)):
            for _ in range(n_walks):
                s = start
                for _ in range(length):
                    options = list(generic_moves(s, facts(s), list(s.blocks)))
                    for j in rng.permutation(len(options))[:12]:
                        new, fail = apply_skill(s, options[j])
                        if fail is None and new.positions != s.positions:
                            s = new
                            t.states.append(s)
                            break
        trials.append(t)
    return trials


class Search:
    """The clause judge and the labelled bank of one intention.

    Per clause it keeps only what ranking needs: how many satisfied and unsatisfied states it
    holds on, and each state's verdicts packed to bits (a pair's counts are read from the
    clauses that may pair), so a language of 10^5 clauses fits in memory and each state is
    judged once."""

    def __init__(self, intention: Intention, trials: list[Trial], clauses):
        self.intention = intention
        self.trials = trials
        self.clauses = clauses
        self.comp = Compiled([Goal((c,)) for c in clauses])
        self.n = len(clauses)
        self.P = np.array([self.comp.possible(tuple(t.scene.objects))[: self.n] for t in trials]).T  # [clause, scene]
        self.tp = np.zeros(self.n, np.int64)  # satisfied states the clause holds on
        self.fp = np.zeros(self.n, np.int64)  # unsatisfied states it holds on
        self.columns: list[np.ndarray] = []  # per state: the clauses' verdicts, packed to bits
        self.labels: list[bool] = []
        self.seen: set[tuple] = set()
        for k, t in enumerate(trials):
            self.add(k, t.states)

    @property
    def y(self) -> np.ndarray:
        return np.array(self.labels, bool)

    def add(self, k: int, states) -> None:
        for s in states:
            key = (k, tuple(sorted(s.positions.items())))
            if key in self.seen:
                continue
            self.seen.add(key)
            f = facts(s)
            col = self.comp.clause_eval(f)[0][: self.n] & self.P[:, k]
            # the state's memo would keep MBs of verdicts per state (as in build_space): dropped once read
            f.memo.pop(self.comp._tag + ("c",), None)
            label = bool(self.intention.satisfied(s))
            (self.tp if label else self.fp)[col] += 1
            self.columns.append(np.packbits(col))
            self.labels.append(label)

    def holds(self, rows: np.ndarray) -> np.ndarray:
        """The verdicts of clauses ``rows`` on every state so far: [row, state]."""
        packed = np.array(self.columns)  # [state, byte]
        return ((packed[:, rows // 8] >> (7 - rows % 8)[None, :]) & 1).astype(bool).T

    def ranked(self, exclude: set[str], n: int) -> list[Goal]:
        """The ``n`` goals (one clause or a pair) that best agree with the labels, not in ``exclude``:
        half by balanced agreement (goals that say what the intention says), half by precision
        (goals narrower than it — "all in the back left corner" for "all in one corner" — hold
        on few of its satisfied states but almost never where it fails)."""
        y = self.y
        pos, neg = y, ~y
        n_pos, n_neg = max(int(pos.sum()), 1), max(int(neg.sum()), 1)
        bits1 = np.array([c.bits for c in self.clauses])
        order = np.lexsort((bits1, -self.tp))[:PAIR_CLAUSES]  # clauses that may pair: most satisfied states
        H = self.holds(order)
        Hp, Hn = H[:, pos].astype(np.int32), H[:, neg].astype(np.int32)
        tp2, fp2 = Hp @ Hp.T, Hn @ Hn.T
        iu = np.triu_indices(len(order), 1)
        tp = np.concatenate([self.tp, tp2[iu]]).astype(float)
        fp = np.concatenate([self.fp, fp2[iu]]).astype(float)
        bits = np.concatenate([bits1, bits1[order][iu[0]] + bits1[order][iu[1]]])
        index = [(int(i),) for i in range(self.n)] + list(zip(order[iu[0]].tolist(), order[iu[1]].tolist(), strict=True))
        agreement = 0.5 * (tp / n_pos + (n_neg - fp) / n_neg)
        precision = np.where(tp > 0, tp / (tp + fp + 1), 0.0)  # +1: one satisfied state is weak evidence
        out: list[Goal] = []
        for measure in (agreement, precision):
            took = 0
            for j in np.lexsort((bits, -tp, -measure)):
                g = Goal(tuple(self.clauses[i] for i in index[j]))
                if g.key in exclude:
                    continue
                exclude.add(g.key)
                out.append(g)
                took += 1
                if took == n // 2:
                    break
        return out


def prior_rank(bits: float, distinct_bits) -> int:
    """1 + the number of the language's enumerated, behaviourally distinct goals (one and two
    clauses, with and without "stays"; the list the learner's space is cut from) with fewer bits."""
    return 1 + int(np.searchsorted(np.asarray(distinct_bits), bits - 1e-6, side="left"))


def coverage(intention: Intention, seed: int = 0, scenes: int = SELECTION_SCENES, test_scenes: int = TEST_SCENES,
             top: int = TOP, rounds: int = ROUNDS, start_keys: set[str] | None = None,
             distinct_bits=None, progress: Callable[[str], None] | None = None,
             prior: FittedPrior | None = None) -> Coverage:
    """The best goal of the language for ``intention`` and its plan success (the oracle).
    ``prior``: whose bits L(z*) and prior rank are reported, and which of equally good goals
    is z* (the fewest bits); None: description length."""
    rng = np.random.default_rng(stable_seed("coverage-bank", seed, intention.name))
    chosen = feasible_scenes(intention, scenes, seed, "selection")
    trials = _bank(intention, chosen, rng)
    clauses = sorted(all_clauses(), key=lambda c: (c.bits, c.key))
    search = Search(intention, trials, clauses)
    starts = [t.start for t in trials]
    tried: dict[str, float] = {}
    goals: dict[str, Goal] = {}
    exclude: set[str] = set()
    for r in range(rounds):
        for g in search.ranked(exclude, top):
            for variant in (g, Goal(g.clauses, True)):
                rate, finals = goal_success(variant, chosen, intention, starts)
                tried[variant.key] = rate
                goals[variant.key] = variant
                for k, end in finals:
                    search.add(k, [end])
        if progress:
            best = max(tried, key=lambda k: (tried[k], -goals[k].bits))
            progress(f"{intention.name}: round {r + 1}/{rounds}, {len(tried)} goals planned, best {tried[best]:.2f}")
    bits = {k: goal_bits(g, prior) for k, g in goals.items()}
    order = sorted(tried, key=lambda k: (-tried[k], bits[k], k))
    z = goals[order[0]]
    held = feasible_scenes(intention, test_scenes, seed, "test")
    success, _ = goal_success(z, held, intention)
    if distinct_bits is None:
        distinct_bits = start_space_info(prior)["distinct_bits"]
    return Coverage(
        intention=intention.name, description=intention.description, goal=z.key, sentence=z.sentence(),
        bits=round(bits[z.key], 2), prior_rank=prior_rank(bits[z.key], distinct_bits),
        in_start_space=bool(start_keys is not None and z.key in start_keys),
        selection_success=round(tried[z.key], 3), success=round(success, 3), test_scenes=len(held),
        planned_goals=len(tried),
        runner_up=[{"goal": k, "selection_success": round(tried[k], 3), "bits": round(bits[k], 2)}
                   for k in order[1:4]])


def coverage_table(intentions: list[Intention], suites: list[str], seed: int = 0, scenes: int = SELECTION_SCENES,
                   test_scenes: int = TEST_SCENES, progress: Callable[[str], None] | None = None,
                   prior: str = "length") -> dict:
    """Coverage of every intention (rows carry their suite) and the means per suite; bits and
    prior ranks under ``prior`` (length, fitted or file:PATH)."""
    fitted = load_prior(prior)
    info = start_space_info(fitted)
    keys, distinct = set(info["keys"]), info["distinct_bits"]
    rows = []
    for k, (it, group) in enumerate(zip(intentions, suites, strict=True), 1):
        c = coverage(it, seed=seed, scenes=scenes, test_scenes=test_scenes, start_keys=keys,
                     distinct_bits=distinct, prior=fitted)
        rows.append({"suite": group, **c.row()})
        if progress:
            progress(f"{k}/{len(intentions)} {group}: {'(held out)' if is_held_out(group) else it.name} done")
    out = []
    for group in dict.fromkeys(suites):
        got = [r for r in rows if r["suite"] == group]
        rates = np.array([r["success"] for r in got])
        rng = np.random.default_rng(stable_seed("coverage-bootstrap", group))
        boot = rates[rng.integers(0, len(rates), (2000, len(rates)))].mean(1)
        out.append({"suite": group, "n": len(got), "mean": round(float(rates.mean()), 3),
                    "ci": [round(float(np.quantile(boot, 0.025)), 3), round(float(np.quantile(boot, 0.975)), 3)],
                    "expressible": int((rates >= EXPRESSIBLE).sum()),
                    "median_bits": round(float(np.median([r["bits"] for r in got])), 2),
                    "in_start_space": int(sum(r["in_start_space"] for r in got))})
    return {"protocol": {"language": spoken(), "prior": prior, "seed": seed, "selection_scenes": scenes, "test_scenes": test_scenes,
                         "scenes": "the protocol's test-scene distribution, kept when the intention is feasible",
                         "plan": "the language's planner, variant 0, executed on the symbolic world model",
                         "search": "one- and two-clause goals, with and without 'stays'",
                         "expressible_threshold": EXPRESSIBLE},
            "suites": out, "intentions": rows}


def explain_intention(intention, seed: int = 0) -> dict:
    """The best goal of the language for an intention, by behaviour (bench/coverage.py), and
    the verdict: expressible when its plan satisfies the intention on ≥ EXPRESSIBLE of the scenes."""
    c = coverage(intention, seed=seed, start_keys=start_space_keys())
    ok = c.success >= EXPRESSIBLE
    verdict = "expressible" if ok else f"not expressible (best: {c.sentence!r}, {c.success:.2f})"
    rows = [{"score": c.success, "key": c.goal, "bits": c.bits, "sentence": c.sentence}]
    rows += [{"score": r["selection_success"], "key": r["goal"], "bits": r["bits"],
              "sentence": parse_goal(r["goal"]).sentence()} for r in c.runner_up]
    return {"sentence": intention.description, "intention": intention.name, "expressible": ok,
            "note": f"{verdict}: plan success of its best goal on {c.test_scenes} feasible test scenes "
                    f"(threshold {EXPRESSIBLE}; runners-up: success on the {SELECTION_SCENES} selection scenes)",
            "matches": rows, "prior_rank": c.prior_rank, "in_start_space": c.in_start_space}



def cached_coverage(intention: Intention, seed: int = 0) -> dict:
    """``coverage(intention).row()`` in the language in force, kept on disk per language (its
    version, and the cache key of the learner's space: the language's sources and node types),
    intention (its class's source) and seed."""
    import hashlib
    import inspect
    from pathlib import Path

    try:
        source = inspect.getsource(type(intention))
    except (OSError, TypeError):
        source = repr(type(intention))
    tag = hashlib.sha256("\0".join([Path(__file__).read_text(), intention.name, intention.description, source,
                                    getattr(getattr(intention, "goal", None), "key", "")]).encode()).hexdigest()[:16]
    return cached_json(cache_path(f"coverage-{seed}-{tag}-v{spoken()}"),
                       lambda: coverage(intention, seed=seed, start_keys=start_space_keys()).row())


def oracle_of(intentions: dict[str, Intention], progress: Callable[[str], None] | None = None) -> dict[str, dict]:
    """Coverage of every intention of a bench (the report's oracle row), cached."""
    out = {}
    for k, (name, it) in enumerate(intentions.items(), 1):
        out[name] = cached_coverage(it)
        if progress:
            progress(f"oracle: coverage {k}/{len(intentions)}")
    return out


def start_space_info(prior: FittedPrior | None = None) -> dict:
    """The lang learners' starting space under ``prior`` (None: description length)."""
    return space_info(0, KEEP, prior=prior)


def start_space_keys() -> set[str]:
    return set(start_space_info()["keys"])


__all__ = ["EXPRESSIBLE", "Coverage", "coverage", "cached_coverage", "coverage_table", "explain_intention", "oracle_of", "feasible_scenes", "goal_success", "start_space_keys"]
