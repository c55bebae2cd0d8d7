"""Judging plans under every hypothesis, and choosing queries by expected information gain.

For a candidate query the learner predicts, with the symbolic world model, the outcome of
each plan; every hypothesis z then gives P(h | z, query) (likelihood.py). The expected
information gain is  EIG = H[Σ_z w_z P(h|z)] − Σ_z w_z H[P(h|z)]  over the answers h:
{A, B, cant_choose, new_scene} for a (scene, plan pair), {stop during step k, no stop,
new_scene} for a (scene, plan).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from activeintent.learners.bayes.facts import Facts, facts, state_key
from activeintent.learners.bayes.hypotheses import Hypothesis
from activeintent.learners.bayes.likelihood import (
    PreferenceModel,
    StopModel,
    preference_probs,
    stop_outcome_probs,
    utility,
)
from activeintent.world import Scene, Skill, WorldState, apply_plan

NEW_SCENE_LAPSE = 0.02  # P(new_scene) when the scene can show z, and 1 − P when it cannot


def judge(hyps: tuple[Hypothesis, ...], f: Facts) -> tuple[np.ndarray, np.ndarray]:
    """(satisfied, score) of one state under every hypothesis (memoised on the facts)."""
    key = ("judge", id(hyps))
    got = f.memo.get(key)
    if got is None:
        sat = np.fromiter((h.holds_f(f) for h in hyps), bool, len(hyps))
        score = np.fromiter((h.score_f(f) for h in hyps), float, len(hyps))
        got = f.memo[key] = (sat, score)
    return got


def first_away(
    hyps: tuple[Hypothesis, ...], steps: list[tuple[Facts, Facts, str, bool]]
) -> np.ndarray:
    """Per hypothesis, the index of the first step that moves away from it (-1: none).

    ``steps``: (facts before, facts after, moved block, executed ok) per step. A failed step
    counts only when it made things worse (its score dropped), as the stop user judges.
    """
    out = np.full(len(hyps), -1)
    for k, (fb, fa, block, ok) in enumerate(steps):
        todo = np.flatnonzero(out < 0)
        if not len(todo):
            break
        if fb is fa:
            continue
        _, sb = judge(hyps, fb)
        _, sa = judge(hyps, fa)
        drop = sa < sb - 1e-9
        for i in todo:
            if drop[i] or (ok and hyps[i].moved_off(fb, fa, block)):
                out[i] = k
    return out


@dataclass
class Outcome:
    """A plan predicted on the symbolic world model."""

    plan: list[Skill]
    final: Facts
    steps: list[tuple[Facts, Facts, str, bool]] = field(default_factory=list)

    @property
    def positions(self) -> np.ndarray:
        """Block positions at the end, [n_blocks, 3]."""
        return np.array([self.final.pos[b] for b in self.final.blocks])


def predict(state: WorldState, plan: list[Skill]) -> Outcome:
    states, fails = apply_plan(state, plan)
    seq = [state, *states]
    steps = [
        (facts(seq[i]), facts(seq[i + 1]), plan[i].block, fails[i] is None) for i in range(len(plan))
    ]
    return Outcome(plan, facts(seq[-1]), steps)


def candidate_plans(
    hyps: tuple[Hypothesis, ...],
    weights: np.ndarray,
    state: WorldState,
    rng: np.random.Generator,
    top_k: int = 24,
    explore: int = 8,
    prefixes: bool = True,
    limit: int = 48,
) -> list[Outcome]:
    """Plans of the most probable hypotheses feasible in the scene (their alternative plans
    and partial plans too) plus those of a few random others, distinct by predicted outcome."""
    scene = state.scene
    order = np.argsort(-weights, kind="stable")
    feasible = [i for i in order if hyps[i].feasible(scene)]
    chosen = feasible[:top_k]
    rest = feasible[top_k:]
    if rest and explore:
        chosen += [rest[j] for j in rng.choice(len(rest), size=min(explore, len(rest)), replace=False)]
    outs: list[Outcome] = []
    seen: set[tuple] = {state_key(facts(state))}  # doing nothing is never worth showing
    for i in chosen:
        for p in hyps[i].plans(state):
            full = predict(state, p)
            options = [full]
            if prefixes:
                options += [Outcome(p[:k], full.steps[k - 1][1], full.steps[:k]) for k in range(len(p) - 1, 0, -1)]
            for o in options:
                key = state_key(o.final)
                if key not in seen:
                    seen.add(key)
                    outs.append(o)
        if len(outs) >= limit:
            break
    return outs[:limit]


def _entropy(p: np.ndarray, axis: int = -1) -> np.ndarray:
    return -(p * np.log(np.clip(p, 1e-300, None))).sum(axis=axis)


def eig(weights: np.ndarray, probs: np.ndarray) -> np.ndarray:
    """EIG per query from P(h | z, query): probs [..., H, O], weights [H]."""
    marginal = np.einsum("h,...ho->...o", weights, probs)
    return _entropy(marginal) - np.einsum("h,...h->...", weights, _entropy(probs))


def with_new_scene(probs: np.ndarray, feasible: np.ndarray) -> np.ndarray:
    """Append the answer new_scene: likely exactly when the scene cannot show z."""
    p_new = np.where(feasible, NEW_SCENE_LAPSE, 1 - NEW_SCENE_LAPSE)
    shape = [1] * (probs.ndim - 2) + [len(feasible), 1]
    p_new = p_new.reshape(shape)
    return np.concatenate([probs * (1 - p_new), np.broadcast_to(p_new, probs.shape[:-1] + (1,))], axis=-1)


def similarity(pos: np.ndarray) -> np.ndarray:
    """σ for every pair of outcomes: mean over blocks of exp(−distance / 5 cm); [P, P]."""
    d = np.linalg.norm(pos[:, None, :, :] - pos[None, :, :, :], axis=-1)
    return np.exp(-d / 0.05).mean(axis=-1)


@dataclass
class Query:
    plans: list[list[Skill]]
    gain: float  # nats


def best_preference_query(
    hyps: tuple[Hypothesis, ...],
    weights: np.ndarray,
    state: WorldState,
    outs: list[Outcome],
    model: PreferenceModel,
) -> Query | None:
    """The pair of plans with the largest EIG (vectorised over all pairs and hypotheses)."""
    if len(outs) < 2:
        return None
    plans = [o.plan for o in outs]
    for h in hyps:
        h.prefetch([o.final for o in outs])
    sat = np.stack([judge(hyps, o.final)[0] for o in outs])  # [P, H]
    score = np.stack([judge(hyps, o.final)[1] for o in outs])
    u = utility(score, sat)
    sim = similarity(np.stack([o.positions for o in outs]))
    i, j = np.triu_indices(len(plans), k=1)
    probs = preference_probs(u[i], u[j], sim[i, j][:, None], model)  # [pairs, H, 3]
    feas = np.array([h.feasible(state.scene) for h in hyps])
    gains = eig(weights, with_new_scene(probs, feas))
    # Among (near-)equal gains prefer short plans: they are cheaper to show.
    cost = np.array([len(plans[a]) + len(plans[b]) for a, b in zip(i, j, strict=False)])
    best = int(np.argmax(gains - 1e-4 * cost))
    return Query([plans[i[best]], plans[j[best]]], float(gains[best]))


def best_stop_query(
    hyps: tuple[Hypothesis, ...],
    weights: np.ndarray,
    state: WorldState,
    outs: list[Outcome],
    model: StopModel,
) -> Query | None:
    """The plan with the largest EIG over the discretised stop outcome."""
    if not outs:
        return None
    for h in hyps:
        h.prefetch([f for o in outs for st in o.steps for f in st[:2]])
    feas = np.array([h.feasible(state.scene) for h in hyps])
    gains = []
    for o in outs:
        probs = stop_outcome_probs(first_away(hyps, o.steps), len(o.plan), model)
        gains.append(float(eig(weights, with_new_scene(probs, feas))) - 1e-4 * len(o.plan))
    best = int(np.argmax(gains))
    return Query([outs[best].plan], gains[best])


def scene_state(scene: Scene, seed: int) -> WorldState:
    from activeintent.world import layout

    return WorldState(positions=layout(scene, seed))
