"""decide's acquisition: the product's EIG (learners/bayes/acquisition.py) and the gains of decide.

For a query q (the trajectories it would show) the signal's observation model gives
P(h | z, q) for every hypothesis z; with the answer "new scene" appended (likely exactly when
the scene cannot show z, up to the learner's assumed error rate ε_ns)::

    EIG(q) = H[Σ_z w_z P(h | z, q)] − Σ_z w_z H[P(h | z, q)]

By the chain rule EIG = I(f; z) + I(h; z | f), f = "the answer is new scene": the first part is
what the scene's feasibility tells, the second what the shown trajectories tell. ``gain="shown"``
keeps only the second, P(f = 0) · EIG over the belief restricted to the z the scene can show.
``gain="decision"`` scores the information about the decision class of z instead
(decision.py: z grouped by which plans satisfy them on scenes the robot will meet);
``gain="shown-decision"`` only what the shown trajectories tell about it, P(f = 0) · I(h; c | f = 0).
``gain="value"`` scores the expected success of the final decision after the answer
(decision.decision_value), ties broken by I(h; c).

Two-step lookahead (``BayesConfig.lookahead = 2``): a query is valued by what it and the best
next query tell together, I(h₁; c) + Σ_{h₁} P(h₁) max_{q₂} I(h₂; c | h₁), with q₂ among every
candidate query of the round (:func:`two_step`): a question that sets up a decisive next one
can beat the one that is best alone.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import BaseModel

from activeintent import ranking
from activeintent.learners.bayes.acquisition import JudgeView, Query, eig, particles
from activeintent.learners.bayes.candidates import Outcome
from activeintent.registry import load_plugin
from activeintent.signals import Judge, Signal
from activeintent.world import describe_plan

_here = Path(__file__).resolve().parent
_decision = load_plugin(_here / "decision.py")
DecisionTable, class_information, decision_value = (_decision.DecisionTable, _decision.class_information,
                                                    _decision.decision_value)
p_new_scene = load_plugin(_here / "needs.py").p_new_scene

GAINS = ("goal", "shown", "decision", "shown-decision", "value")
VALUE_TIE = 1e-4  # gain = "value": among queries of (near-)equal value, the one that tells more about c
SHORT_PLANS = 1e-4  # per step shown: among (near-)equal gains prefer short plans, quicker to watch


def with_new_scene(probs: np.ndarray, feasible: np.ndarray, error: float, refuse: float = 0.0) -> np.ndarray:
    """Append the answer "new scene" to P(h | z): P = 1 − ε where z cannot be shown, ε where it can
    (with ``refuse`` = q(s) > 0, the needs belief's doubt: needs.py)."""
    p_new = p_new_scene(feasible, error, refuse)[:, None]
    return np.concatenate([probs * (1 - p_new), p_new], axis=1)


LOOK_FIRST = 16  # the best one-step queries that get the two-step value


def look_particles(weights: np.ndarray) -> np.ndarray:
    """The particles of the two-step lookahead: the likeliest z holding 99 % (at most 256)."""
    return particles(weights, mass=0.99, cap=256)


@dataclass
class Scored:
    """Every candidate query of one state, kept for the two-step lookahead: per query its outcomes,
    its one-step gain and P(h | z, q) ("new scene" included) over :func:`look_particles`."""

    outs: list[Outcome]
    combos: list[tuple[int, ...]]
    gains: np.ndarray
    tables: list[np.ndarray]


def _information_many(w: np.ndarray, pool: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """I(h; c) in nats for every query of ``pool`` [Z, Q, O] (z sorted by class, a class's first
    row at ``starts``) under weights ``w`` [Z]: H[P(h)] − Σ_c W_c H[P(h | c)]."""
    joint = np.add.reduceat(w[:, None, None] * pool, starts, axis=0)  # [C, Q, O]: W_c P(h | c)
    mass = np.add.reduceat(w, starts)[:, None, None]
    marginal = joint.sum(axis=0)
    h_marg = -(marginal * np.log(np.clip(marginal, 1e-300, None))).sum(axis=1)
    cond = np.where(joint > 0, joint / np.clip(mass, 1e-300, None), 1.0)
    return h_marg + (joint * np.log(cond)).sum(axis=(0, 2))


def stack_tables(tables: list[np.ndarray]) -> np.ndarray:
    """[Z, Q, O]: the queries' P(h | z) side by side, answers padded with P = 0."""
    width = max(t.shape[1] for t in tables)
    pool = np.zeros((tables[0].shape[0], len(tables), width))
    for q, t in enumerate(tables):
        pool[:, q, :t.shape[1]] = t
    return pool


def two_step(scored: list[Scored], pool: np.ndarray, weights: np.ndarray, classes: np.ndarray,
             first: int = LOOK_FIRST) -> tuple[int, int, float]:
    """(which Scored, which of its queries, value): among the ``first`` best one-step queries of
    ``scored``, the one with the largest I(h₁; c) + Σ_{h₁} P(h₁) max_{q₂ ∈ pool} I(h₂; c | h₁).
    ``weights`` and ``classes`` are over the look particles (the rows of the tables and pool)."""
    order = np.argsort(classes, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(classes[order]) != 0])
    pool = pool[order]
    w = weights / weights.sum()
    ws = w[order]
    flat = [(i, j, float(g)) for i, sc in enumerate(scored) for j, g in enumerate(sc.gains)]
    keys = np.array([g for _, _, g in flat])
    best: tuple[int, int, float] | None = None
    for n in ranking.order(keys)[:first]:
        i, j, _ = flat[n]
        table = scored[i].tables[j][order]
        p_h = ws @ table
        value = float(_information_many(ws, table[:, None, :], starts)[0])
        for a in np.flatnonzero(p_h > 1e-9):
            post = ws * table[:, a] / p_h[a]
            value += float(p_h[a]) * float(_information_many(post, pool, starts).max())
        value -= SHORT_PLANS * sum(len(scored[i].outs[k].plan) for k in scored[i].combos[j])
        if best is None or ranking.greater(value, best[2]):
            best = (i, j, value)
    return best  # type: ignore[return-value]


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
    gain: str = "goal",
    classes: np.ndarray | None = None,
    refuse: float = 0.0,
    scored: list[Scored] | None = None,
    table: DecisionTable | None = None,
) -> Query | None:
    """The query (``signal.shows`` distinct outcomes) with the largest EIG; ``choose="random"``
    picks uniformly among the candidates instead (same planner, same belief update). EIG is
    computed over the ``cap`` most probable hypotheses when H is larger (see :func:`particles`).
    ``scored``: also append every candidate's table for :func:`two_step`."""
    combos = list(itertools.combinations(range(len(outs)), signal.shows))
    if not combos:
        return None
    if len(combos) > max_queries:  # keep selection time bounded: a seeded subset
        keep = rng.choice(len(combos), size=max_queries, replace=False)
        combos = [combos[i] for i in sorted(keep)]
    if choose == "random":
        pick = combos[int(rng.integers(len(combos)))]
        return Query([outs[i] for i in pick], float("nan"))
    if gain not in GAINS:
        raise ValueError(f"unknown gain {gain!r}; valid gains: {', '.join(GAINS)}")
    if (gain.endswith("decision") or gain == "value") and classes is None:
        raise ValueError(f"gain={gain!r} needs the hypotheses' decision classes")
    if gain == "value" and table is None:
        raise ValueError("gain='value' needs the decision table of the deployment scenes")
    look = look_particles(weights) if scored is not None else None
    if len(weights) > cap:
        idx = particles(weights, cap=cap)
        if look is not None:  # the look particles are a prefix of the same ranking: all in idx
            at = np.searchsorted(idx, look)
            assert np.array_equal(idx[np.minimum(at, len(idx) - 1)], look), "look particles outside the EIG particles"
            look = at
        judge, feasible = JudgeView(judge, idx), feasible[idx]  # type: ignore[assignment]
        weights = weights[idx] / weights[idx].sum()
        if classes is not None:
            classes = np.unique(classes[idx], return_inverse=True)[1].reshape(-1)
        if table is not None:
            table = table.take(idx)
    if gain.startswith("shown"):
        p_answer = 1 - p_new_scene(feasible, new_scene_error, refuse)
        p_shown = float(weights @ p_answer)
        w_shown = weights * p_answer / p_shown
    gains = np.empty(len(combos))
    tables: list[np.ndarray] = []
    predicted = signal.predictive_many([[outs[i].traj for i in combo] for combo in combos], judge, model)
    for n, (combo, probs) in enumerate(zip(combos, predicted, strict=True)):
        full = None if gain.startswith("shown") and look is None else with_new_scene(
            probs, feasible, new_scene_error, refuse)  # P(h | z) with "new scene"
        if gain == "shown":
            g = p_shown * eig(w_shown, probs)
        elif gain == "shown-decision":
            g = p_shown * class_information(w_shown, probs, classes)  # type: ignore[arg-type]
        elif gain == "decision":
            g = class_information(weights, full, classes)  # type: ignore[arg-type]
        elif gain == "value":
            g = decision_value(weights, full, table) + VALUE_TIE * class_information(weights, full, classes)  # type: ignore[arg-type]
        else:
            g = eig(weights, full)  # type: ignore[arg-type]
        if look is not None:
            tables.append(full[look])  # type: ignore[index]
        gains[n] = g - SHORT_PLANS * sum(len(outs[i].plan) for i in combo)
    if scored is not None:
        scored.append(Scored(outs, combos, gains, tables))
    order = ranking.order(gains)
    best = combos[order[0]]
    alternatives = [
        {"plans": [describe_plan(outs[i].plan) for i in combos[j]],
         "eig_nats": round(float(gains[j]), 4)}
        for j in order[1:4]
    ]
    return Query([outs[i] for i in best], float(gains[order[0]]), alternatives)
