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
from activeintent.memo import BoundedCache
from activeintent.world import Skill, WorldState
from activeintent.world.skills import skill_key
from activeintent.world.trajectory import Trajectory


@dataclass
class Outcome:
    """A plan with its predicted τ."""

    plan: list[Skill]
    traj: Trajectory

    @property
    def key(self) -> tuple:
        return state_key(facts(self.traj.outcome))


# The final answers predict the same plans on the same test scenes after every signal, and
# query selection revisits them: ≈ 60 % of predictions repeat within an episode.
_PREDICTED: BoundedCache[tuple, Outcome] = BoundedCache(8192)


def predict(state: WorldState, plan: list[Skill]) -> Outcome:
    """``plan`` from ``state`` on the symbolic world model (kept by the exact positions, in
    order, and the skills: the same predicted τ, shared)."""
    key = (tuple(state.positions.items()), tuple(skill_key(s) for s in plan))
    got = _PREDICTED.get_or_make(key, lambda: Outcome(list(plan), symbolic_trajectory(state.scene, state, plan)))
    return Outcome(list(got.plan), got.traj)


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
