"""Longer stop queries for decide-stop's variants: a chain of two likely goals' plans
(``chains``), and plans grown step by step to split the belief (``split``)."""

from __future__ import annotations

import numpy as np

from activeintent import ranking
from activeintent.goals.facts import facts, state_key
from activeintent.learners.bayes.candidates import Outcome, predict
from activeintent.learners.bayes.hypotheses import Hypothesis
from activeintent.world import Skill, WorldState, apply_skill


def chained_plans(
    hyps: tuple[Hypothesis, ...],
    weights: np.ndarray,
    state: WorldState,
    feasible: np.ndarray,
    first: int = 4,
    limit: int = 8,
    seen: set[tuple] | None = None,
) -> list[Outcome]:
    """Longer plans for a stop query: the plan of one of the ``first`` most probable feasible
    hypotheses z_i, then from where it ends the plan of another of them z_j. Where the person
    stops (in the first part, the second, or not at all) then tells the likely goals apart by
    *when*, not only whether. ``seen``: outcome keys already offered (not repeated)."""
    order = ranking.order(weights, ranking.WEIGHT_DECIMALS)
    top = order[feasible[order]][:first].tolist()
    seen = set(seen or ()) | {state_key(facts(state))}
    outs: list[Outcome] = []
    for i in top:
        head = hyps[i].plan(state)
        if not head:
            continue
        middle = predict(state, head).traj.outcome
        for j in top:
            tail = hyps[j].plan(middle) if j != i else None
            if not tail:
                continue
            o = predict(state, head + tail)
            if o.key not in seen:
                seen.add(o.key)
                outs.append(o)
            if len(outs) >= limit:
                return outs
    return outs


def split_plans(
    hyps: tuple[Hypothesis, ...],
    weights: np.ndarray,
    state: WorldState,
    feasible: np.ndarray,
    judge,
    idx: np.ndarray,
    starts: int = 3,
    max_len: int = 6,
    sources: int = 8,
    seen: set[tuple] | None = None,
    classes: np.ndarray | None = None,
) -> list[Outcome]:
    """Stop queries built to split the belief: a plan grown one step at a time, each step the
    move (among the steps of the plans of the ``sources`` likeliest z not yet moved away from)
    that moves away from as close to half of the remaining belief as it can. Where the person
    stops then tells apart up to ``max_len`` + 1 groups of z (≈ 2 bits with exact answers), not
    the two of a plan for one z. ``idx``: the particles judged (the likely z); ``starts``: plans
    grown from the best different first steps. ``seen``: outcome keys already offered.
    ``classes`` (the decision classes of z): split the classes, not z within one class."""
    idx = idx[feasible[idx]]
    if len(idx) < 2:
        return []
    w = weights[idx] / weights[idx].sum()
    cls = None if classes is None else np.unique(classes[idx], return_inverse=True)[1].reshape(-1)

    def gain(away: np.ndarray, alive: np.ndarray) -> float:
        g = _split_bits(float(w[away].sum()), float(w[alive].sum()))
        if cls is not None:  # I(stop step; class) = H(step) − H(step | class), exact answers
            g -= sum(_split_bits(float(w[away & (cls == c)].sum()), float(w[alive & (cls == c)].sum()))
                     for c in np.unique(cls[away]))
        return g

    def scored(cur: WorldState, alive: np.ndarray, options: list[Skill]):
        """(gain, step, state after, z it moves away from) per step that moves something."""
        for step in options:
            after, fail = apply_skill(cur, step)
            if fail is None and after.positions != cur.positions:
                away = judge.step_away(facts(cur), facts(after), step.block)[idx] & alive
                yield gain(away, alive), step, after, away

    everyone = np.ones(len(idx), dtype=bool)
    # the plans start from different moves: the best first steps, best first
    first = [step for _, step, _, _ in sorted(scored(state, everyone, _next_steps(hyps, idx, everyone, w, state, sources)),
                                              key=lambda g: -g[0])]
    seen = set(seen or ()) | {state_key(facts(state))}
    outs: list[Outcome] = []
    for s in range(starts):
        plan: list[Skill] = []
        alive, cur = everyone, state
        for t in range(max_len):
            options = first[s:s + 1] if t == 0 else _next_steps(hyps, idx, alive, w, cur, sources)
            best = None
            for cand in scored(cur, alive, options):
                if best is None or cand[0] > best[0] + 1e-12:
                    best = cand
            if best is None or best[0] < 1e-3:
                break
            plan.append(best[1])
            cur, alive = best[2], alive & ~best[3]
            if not alive.any():
                break
        if plan:
            o = predict(state, plan)
            if o.key not in seen:
                seen.add(o.key)
                outs.append(o)
    return outs


def _split_bits(x: float, a: float) -> float:
    """a · H2(x / a): what splitting mass x off the remaining mass a adds to the partition's entropy."""
    if x <= 0 or x >= a:
        return 0.0
    p = x / a
    return a * float(-(p * np.log2(p) + (1 - p) * np.log2(1 - p)))


def _next_steps(hyps, idx, alive, w, state: WorldState, sources: int) -> list[Skill]:
    """Distinct steps of the plans, from ``state``, of the likeliest z still alive."""
    order = [int(i) for i in np.argsort(-w, kind="stable") if alive[i]][:sources]
    steps: dict[str, Skill] = {}
    for i in order:
        for p in hyps[idx[i]].plans(state):
            for step in p:
                steps.setdefault(repr(step), step)
    return list(steps.values())

