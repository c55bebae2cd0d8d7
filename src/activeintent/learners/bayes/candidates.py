"""The planner of the Bayesian learners: candidate plans worth showing in a scene.

Plans come from the most probable hypotheses feasible in the scene (their alternative and
partial plans too) plus a few random others; each is predicted on the symbolic env, so the
learner knows what τ it would show. Outcomes that end in the same state are kept once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from activeintent import ranking
from activeintent.envs.symbolic import symbolic_trajectory
from activeintent.goals.facts import facts, state_key
from activeintent.learners.bayes.hypotheses import Hypothesis
from activeintent.world import Skill, WorldState
from activeintent.world.trajectory import Trajectory


@dataclass
class Outcome:
    """A plan with its predicted τ."""

    plan: list[Skill]
    traj: Trajectory

    @property
    def key(self) -> tuple:
        return state_key(facts(self.traj.outcome))


def predict(state: WorldState, plan: list[Skill]) -> Outcome:
    return Outcome(list(plan), symbolic_trajectory(state.scene, state, plan))


def candidate_plans(
    hyps: tuple[Hypothesis, ...],
    weights: np.ndarray,
    state: WorldState,
    rng: np.random.Generator,
    top_k: int = 16,
    explore: int = 6,
    prefixes: bool = True,
    limit: int = 36,
    feasible: np.ndarray | None = None,
) -> list[Outcome]:
    """Distinct predicted outcomes of the plans of likely (and a few random) hypotheses;
    ``feasible``: the hypotheses the scene can show (default: asked one by one)."""
    if feasible is None:
        scene = state.scene
        feasible = np.fromiter((h.feasible(scene) for h in hyps), bool, len(hyps))
    order = ranking.order(weights, ranking.WEIGHT_DECIMALS)
    feasible = order[feasible[order]].tolist()
    chosen = feasible[:top_k]
    rest = feasible[top_k:]
    if rest and explore:
        chosen += [rest[j] for j in rng.choice(len(rest), size=min(explore, len(rest)), replace=False)]
    outs: list[Outcome] = []
    seen: set[tuple] = {state_key(facts(state))}  # doing nothing is never worth showing
    for i in chosen:
        for p in hyps[i].plans(state):
            options = [p] + ([p[:k] for k in range(len(p) - 1, 0, -1)] if prefixes else [])
            for plan in options:
                o = predict(state, plan)
                if o.key not in seen:
                    seen.add(o.key)
                    outs.append(o)
        if len(outs) >= limit:
            break
    return outs[:limit]


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
