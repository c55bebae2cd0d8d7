"""Choices among floats that come out the same on every machine.

Two quantities equal in exact arithmetic (two plans' expected success Σ_z w_z 1[z satisfied],
two queries' EIG) often differ in the last bits when computed: the order of a BLAS dot product
depends on the CPU kernel (``OPENBLAS_CORETYPE``) and the thread count, a SIMD ``exp`` on the
CPU's instruction set. An ``argmax`` over such near-ties picks by float noise, so an episode
would depend on the machine. Every choice the learners, users and scoring make goes through
here instead: values are rounded to a grid far coarser than float noise and far finer than
any difference that matters, and ties on the grid are broken by position (the caller's order,
itself deterministic).
"""

from __future__ import annotations

import numpy as np

DECIMALS = 9  # 1e-9: float noise is ~1e-16 of the value; meaningful differences are ≥ 1e-6
WEIGHT_DECIMALS = 12  # for belief weights (they sum to 1): finer, so small weights keep their order


def quantised(values, decimals: int = DECIMALS) -> np.ndarray:
    """``values`` on a grid of 10^-decimals (−0 and +0 the same)."""
    return np.round(np.asarray(values, dtype=float), decimals) + 0.0


def order(values, decimals: int = DECIMALS) -> np.ndarray:
    """Indices from the largest value to the smallest; ties (on the grid) by index."""
    q = quantised(values, decimals)
    return np.lexsort((np.arange(len(q)), -q))


def argmax(values, decimals: int = DECIMALS) -> int:
    """Index of the largest value on the grid; the first one among ties."""
    q = quantised(values, decimals)
    return int(np.flatnonzero(q == q.max())[0])


def greater(a: float, b: float, decimals: int = DECIMALS) -> bool:
    """``a > b`` beyond float noise."""
    return float(quantised(a, decimals)) > float(quantised(b, decimals))


PLAN_STEP_COST = 1e-6  # a final answer's tie-break: among equally good plans, the shorter


def best_plan(values, plan_lengths) -> int:
    """Index of the final answer: the largest value (an expected success, a reward) less
    PLAN_STEP_COST per step, so that of two plans as good as each other the shorter is run;
    the first among ties."""
    return argmax(np.asarray(values, dtype=float) - PLAN_STEP_COST * np.asarray(plan_lengths, dtype=float))
