"""The preference user's choice model: exact probabilities of h ∈ {A, B, cant_choose}.

Shared by the simulated preference user (which samples from it) and by learners that need
the likelihood P(h | z) of a preference under a hypothesised intention z.

Utility of an outcome (final state s) under an intention::

    u(s) = (score(s) + 1[satisfied(s)]) / 2            ∈ [0, 1]

Given u_a, u_b, d = u_a − u_b and the similarity σ ∈ [0, 1] of the two outcomes, the three
answers have utilities::

    U_A = d / 2,    U_B = −d / 2,    U_C = m − |d| / 2      (C = cant_choose)

and the user answers with Boltzmann-rational probabilities (rationality β)::

    P(o) ∝ exp(β · U_o + κ · σ · 1[o = C])

m ≥ 0 is the indifference margin (differences in u below m are not worth a choice) and
κ ≥ 0 the similarity confusion: near-identical outcomes add up to κ to the log-odds of
"can't choose", whatever β. As β → ∞ the answer becomes deterministic: A if d > m, B if
d < −m, cant_choose if |d| < m. β = ∞ is the exact user: that rule, with an exact tie
(|d| ≤ 1e-9) also answered cant_choose when m = 0.
"""

from __future__ import annotations

import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import WorldState

CHOICES: tuple[str, str, str] = ("A", "B", "cant_choose")
SIMILARITY_LENGTH = 0.05  # metres: a block 5 cm away from its counterpart is e⁻¹ as similar
TIE = 1e-9


def outcome_utility(intention: Intention, state: WorldState) -> float:
    """u(s) = (score(s) + 1[satisfied(s)]) / 2 ∈ [0, 1]."""
    score = float(np.clip(intention.score(state), 0.0, 1.0))
    return 0.5 * (score + (1.0 if intention.satisfied(state) else 0.0))


def outcome_similarity(a: WorldState, b: WorldState, length: float = SIMILARITY_LENGTH) -> float:
    """σ ∈ [0, 1]: mean over the blocks of exp(−distance between their two positions / length).

    1 when both outcomes are identical; about 0 when every block ends ≥ 15 cm from where it
    ends in the other outcome. Only blocks present in both states count (none → 0).
    """
    common = [n for n in a.blocks if n in b.positions]
    if not common:
        return 0.0
    dists = [float(np.linalg.norm(a.pos(n) - b.pos(n))) for n in common]
    return float(np.mean([math.exp(-d / length) for d in dists]))


def preference_probabilities(
    u_a: float,
    u_b: float,
    similarity: float = 0.0,
    beta: float = math.inf,
    indifference: float = 0.05,
    confusion: float = 1.0,
) -> dict[str, float]:
    """P(h) for h ∈ {A, B, cant_choose} under the model in the module docstring."""
    d = u_a - u_b
    if math.isinf(beta):
        if abs(d) < indifference or abs(d) <= TIE:
            return {"A": 0.0, "B": 0.0, "cant_choose": 1.0}
        return {"A": 1.0, "B": 0.0, "cant_choose": 0.0} if d > 0 else {"A": 0.0, "B": 1.0, "cant_choose": 0.0}
    logits = np.array(
        [
            beta * d / 2,
            -beta * d / 2,
            beta * (indifference - abs(d) / 2) + confusion * float(np.clip(similarity, 0.0, 1.0)),
        ]
    )
    p = np.exp(logits - logits.max())
    p /= p.sum()
    return dict(zip(CHOICES, (float(v) for v in p), strict=True))


def sample_choice(probabilities: dict[str, float], rng: np.random.Generator) -> str:
    """One draw of h from ``probabilities`` (one uniform number from ``rng``)."""
    u = rng.random()
    total = 0.0
    for choice in CHOICES:
        total += probabilities[choice]
        if u < total:
            return choice
    return max(CHOICES, key=lambda c: probabilities[c])  # rounding at the top end
