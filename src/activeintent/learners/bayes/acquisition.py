"""Acquisition: which query to ask, by expected information gain (or at random, the baseline).

For a query q (the trajectories it would show) the signal's observation model gives
P(h | z, q) for every hypothesis z; with the answer "new scene" appended (likely exactly when
the scene cannot show z, up to the learner's assumed error rate ε_ns)::

    EIG(q) = H[Σ_z w_z P(h | z, q)] − Σ_z w_z H[P(h | z, q)]

The candidate queries come from the planner (candidates.py); the "new scene" answer is what
makes a scene that cannot show the likely z a poor question.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
from pydantic import BaseModel

from activeintent import ranking
from activeintent.learners.bayes.candidates import Outcome
from activeintent.signals import Judge, Signal
from activeintent.world import describe_plan

SHORT_PLANS = 1e-4  # per step shown: among (near-)equal gains prefer short plans, quicker to watch


def _entropy(p: np.ndarray) -> np.ndarray:
    return -(p * np.log(np.clip(p, 1e-300, None))).sum(axis=-1)


def eig(weights: np.ndarray, probs: np.ndarray) -> float:
    """EIG in nats from P(h | z): probs [H, O], weights [H]."""
    return float(_entropy(weights @ probs) - weights @ _entropy(probs))


def p_new_scene(feasible: np.ndarray, error: float) -> np.ndarray:
    """P(new scene | z): 1 − ε where z cannot be shown in the scene, ε where it can."""
    return np.where(feasible, error, 1 - error)


def p_answered(feasible: np.ndarray, error: float) -> np.ndarray:
    """1 − P(new scene | z): the user answers about what was shown."""
    return np.where(feasible, 1 - error, error)


def with_new_scene(probs: np.ndarray, feasible: np.ndarray, error: float) -> np.ndarray:
    """Append the answer "new scene" to P(h | z): P = 1 − ε where z cannot be shown, ε where it can."""
    p_new = p_new_scene(feasible, error)[:, None]
    return np.concatenate([probs * (1 - p_new), p_new], axis=1)


class JudgeView:
    """The judge restricted to hypotheses ``idx`` (the particles acquisition looks at)."""

    def __init__(self, judge: Judge, idx: np.ndarray):
        self.inner, self.idx, self.size = judge, idx, len(idx)

    def utility(self, state):
        return self.inner.utility(state)[self.idx]

    def first_away(self, traj):
        return self.inner.first_away(traj)[self.idx]


def particles(weights: np.ndarray, mass: float = 1 - 1e-4, cap: int = 4000) -> np.ndarray:
    """The most probable hypotheses holding ``mass`` of the belief (at most ``cap``): EIG over
    them approximates EIG over H (the neglected tail carries < 1 − mass, or is cut at ``cap``)."""
    if len(weights) <= cap:
        return np.arange(len(weights))
    top = ranking.order(weights, ranking.WEIGHT_DECIMALS)[:cap]
    n = int(np.searchsorted(np.cumsum(weights[top]), mass * weights.sum())) + 1
    return np.sort(top[:min(n, cap)])


@dataclass
class Query:
    """The trajectories to show (as plans) and why: the EIG of this query and the best others."""

    outcomes: list[Outcome]
    gain: float  # nats
    alternatives: list[dict] = field(default_factory=list)

    @property
    def plans(self):
        return [o.plan for o in self.outcomes]


def select_query(
    signal: Signal,
    model: BaseModel,
    judge: Judge,
    weights: np.ndarray,
    feasible: np.ndarray,
    outs: list[Outcome],
    new_scene_error: float,
    rng: np.random.Generator,
    choose: str = "eig",
    max_queries: int = 700,
    cap: int = 4000,
) -> Query | None:
    """The query (``signal.shows`` distinct outcomes) with the largest EIG; ``choose="random"``
    picks uniformly among the candidates instead (same planner, same belief update). EIG is
    computed over the ``cap`` most probable hypotheses when H is larger (see :func:`particles`)."""
    combos = list(itertools.combinations(range(len(outs)), signal.shows))
    if not combos:
        return None
    if len(combos) > max_queries:  # keep selection time bounded: a seeded subset
        keep = rng.choice(len(combos), size=max_queries, replace=False)
        combos = [combos[i] for i in sorted(keep)]
    if choose == "random":
        pick = combos[int(rng.integers(len(combos)))]
        return Query([outs[i] for i in pick], float("nan"))
    if len(weights) > cap:
        idx = particles(weights, cap=cap)
        judge, feasible = JudgeView(judge, idx), feasible[idx]  # type: ignore[assignment]
        weights = weights[idx] / weights[idx].sum()
    gains = np.empty(len(combos))
    predicted = signal.predictive_many([[outs[i].traj for i in combo] for combo in combos], judge, model)
    for n, (combo, probs) in enumerate(zip(combos, predicted, strict=True)):
        g = eig(weights, with_new_scene(probs, feasible, new_scene_error))
        gains[n] = g - SHORT_PLANS * sum(len(outs[i].plan) for i in combo)
    order = ranking.order(gains)
    best = combos[order[0]]
    alternatives = [
        {"plans": [describe_plan(outs[i].plan) for i in combos[j]],
         "eig_nats": round(float(gains[j]), 4)}
        for j in order[1:4]
    ]
    return Query([outs[i] for i in best], float(gains[order[0]]), alternatives)
