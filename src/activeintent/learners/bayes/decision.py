"""Decision classes: hypotheses z grouped by what they would have the robot do.

The learner is scored by the plan it runs on scenes it has not seen, not by naming z. Two
hypotheses that the same plans satisfy on every scene the robot will meet need not be told
apart. The learner draws its own deployment scenes from the protocol's public test-scene
distribution (``protocol.sample_test_scene``, with its own seed: never the episode's test
scenes), takes there the plans of its likely hypotheses (the plans its final answer chooses
among) and gives each z a signature: per scene, which of those plans satisfy z. Equal
signatures form one class c; acquisition with ``gain="decision"`` scores a query by the
information its answer h gives about c (EC²-style equivalence classes, measured by mutual
information)::

    I(h; c) = H[Σ_c W_c P(h | c)] − Σ_c W_c H[P(h | c)],   P(h | c) = Σ_{z∈c} w_z P(h | z) / W_c
"""

from __future__ import annotations

import numpy as np

from activeintent.goals.facts import facts
from activeintent.learners.bayes.candidates import candidate_plans
from activeintent.protocol import sample_test_scene
from activeintent.world import Scene, WorldState, layout


def deployment_states(seed: int, n: int) -> list[WorldState]:
    """``n`` scenes of the public test-scene distribution, laid out, from the learner's own seed."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        scene: Scene = sample_test_scene(rng)
        out.append(WorldState(positions=layout(scene, int(rng.integers(2**31)))))
    return out


def decision_classes(hyps, weights: np.ndarray, judge, states: list[WorldState], rng: np.random.Generator,
                     top_k: int = 10, limit: int = 36) -> np.ndarray:
    """Class index per hypothesis: equal when, on every deployment state, the same candidate
    plans (those of the ``top_k`` likely hypotheses the state can show) satisfy them."""
    columns = []
    for state in states:
        feasible = judge.feasible(tuple(state.scene.objects))
        outs = candidate_plans(hyps, weights * feasible, state, rng, top_k=top_k, explore=0, prefixes=False,
                               limit=limit, feasible=feasible)
        columns.append(feasible[:, None])
        for o in outs:
            columns.append((judge.judge(facts(o.traj.outcome))[0] & feasible)[:, None])
    if not columns:
        return np.zeros(len(weights), dtype=int)
    signature = np.packbits(np.concatenate(columns, axis=1), axis=1)
    _, classes = np.unique(signature, axis=0, return_inverse=True)
    return classes.reshape(-1)


def class_information(weights: np.ndarray, probs: np.ndarray, classes: np.ndarray) -> float:
    """I(h; c) in nats: probs [H, O] = P(h | z), weights [H], classes [H]."""
    n = int(classes.max()) + 1
    mass = np.bincount(classes, weights=weights, minlength=n)  # W_c
    joint = np.stack([np.bincount(classes, weights=weights * probs[:, j], minlength=n)  # W_c P(h | c)
                      for j in range(probs.shape[1])], axis=1)
    marginal = joint.sum(axis=0)
    keep = mass > 0
    cond = joint[keep] / mass[keep, None]
    h_marg = -(marginal * np.log(np.clip(marginal, 1e-300, None))).sum()
    h_cond = -(cond * np.log(np.clip(cond, 1e-300, None))).sum(axis=1)
    return float(h_marg - mass[keep] @ h_cond)
