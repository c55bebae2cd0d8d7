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

``gain="value"`` scores the decision itself instead: the expected success, after the answer h,
of the final answer on those scenes (per scene the plan, doing nothing included, that the
belief given h and "z can be shown here" most expects to satisfy z), averaged over scenes::

    V(q) = (1/S) Σ_s Σ_h P(h) max_p P(p satisfies z | h, s shows z)
"""

from __future__ import annotations

from dataclasses import dataclass

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


@dataclass
class DecisionTable:
    """Per deployment state: which z it can show [Z], and which candidate plans satisfy each z
    there [Z, P] (column 0: doing nothing; then the plans of the likely z)."""

    feasible: list[np.ndarray]
    satisfied: list[np.ndarray]

    def take(self, idx: np.ndarray) -> DecisionTable:
        return DecisionTable([f[idx] for f in self.feasible], [s[idx] for s in self.satisfied])


def decision_table(hyps, weights: np.ndarray, judge, states: list[WorldState], rng: np.random.Generator,
                   top_k: int = 10, limit: int = 36) -> DecisionTable:
    """The candidate plans of the ``top_k`` likely hypotheses each deployment state can show,
    judged under every hypothesis."""
    table = DecisionTable([], [])
    for state in states:
        feasible = judge.feasible(tuple(state.scene.objects))
        outs = candidate_plans(hyps, weights * feasible, state, rng, top_k=top_k, explore=0, prefixes=False,
                               limit=limit, feasible=feasible)
        cols = [judge.judge(facts(state))[0]] + [judge.judge(facts(o.traj.outcome))[0] for o in outs]
        table.feasible.append(feasible)
        table.satisfied.append(np.stack(cols, axis=1) & feasible[:, None])
    return table


def classes_of(table: DecisionTable, size: int) -> np.ndarray:
    """Class index per hypothesis: equal when, on every deployment state, the same candidate
    plans satisfy them (doing nothing left out)."""
    columns = []
    for feasible, satisfied in zip(table.feasible, table.satisfied, strict=True):
        columns.append(feasible[:, None])
        columns.append(satisfied[:, 1:])
    if not columns:
        return np.zeros(size, dtype=int)
    signature = np.packbits(np.concatenate(columns, axis=1), axis=1)
    _, classes = np.unique(signature, axis=0, return_inverse=True)
    return classes.reshape(-1)


def decision_classes(hyps, weights: np.ndarray, judge, states: list[WorldState], rng: np.random.Generator,
                     top_k: int = 10, limit: int = 36) -> np.ndarray:
    """Class index per hypothesis: equal when, on every deployment state, the same candidate
    plans (those of the ``top_k`` likely hypotheses the state can show) satisfy them."""
    return classes_of(decision_table(hyps, weights, judge, states, rng, top_k, limit), len(weights))


def decision_value(weights: np.ndarray, probs: np.ndarray, table: DecisionTable) -> float:
    """V(q): probs [H, O] = P(h | z), weights [H]; the expected success of the final answer after
    the answer, per deployment state, averaged (a state that can show no z counts 0)."""
    if not table.feasible:
        return 0.0
    joint = weights[:, None] * probs  # [Z, O]: w_z P(h | z)
    p_h = joint.sum(axis=0)
    total = 0.0
    for feasible, satisfied in zip(table.feasible, table.satisfied, strict=True):
        shown = joint * feasible[:, None]
        mass = shown.sum(axis=0)  # [O]: P(h, s shows z)
        best = (shown.T @ satisfied).max(axis=1)  # [O]: max_p P(h, p satisfies z)
        total += float((p_h * np.where(mass > 0, best / np.where(mass > 0, mass, 1.0), 0.0)).sum())
    return total / len(table.feasible)


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
