"""The belief over intentions z: log weights, Bayes' rule, entropy, hypotheses added later.

Prior (``prior="length"``): P(z) ∝ 2^(−L(z)), L the description length in bits of z in the
grammar (docs/bayes.md) — a general simplicity principle, not a choice of intentions.
``prior="uniform"`` is the ablation. The goal language's hypotheses may carry bits under a
prior fitted to a corpus of requests (goals/prior.py: ``fitted``, ``file:PATH``): P(z) ∝ 2^(−bits)
reads them the same way.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from activeintent import ranking
from activeintent.learners.bayes.hypotheses import Hypothesis

Prior = Literal["length", "uniform"]


def raw_log_prior(hyps: tuple[Hypothesis, ...], prior: str = "length") -> np.ndarray:
    """log P(z) up to one constant: −L(z) ln 2 (length, or the fitted prior the hypotheses'
    bits were computed under) or 0 (uniform)."""
    if prior == "uniform":
        return np.zeros(len(hyps))
    if prior in ("length", "fitted") or prior.startswith("file:"):
        return -np.array([h.bits for h in hyps]) * math.log(2)
    raise ValueError(f"unknown prior {prior!r}; valid priors: length, uniform, fitted, file:PATH")


def log_prior(hyps: tuple[Hypothesis, ...], prior: str = "length") -> np.ndarray:
    lw = raw_log_prior(hyps, prior)
    return lw - np.logaddexp.reduce(lw)


class Belief:
    """w_z ∝ P(z) Π_k P(h_k | z), kept in logs."""

    def __init__(self, hyps: tuple[Hypothesis, ...], prior: str = "length"):
        self.hyps = hyps
        self.prior = prior
        raw = raw_log_prior(hyps, prior)
        self.log_norm = float(np.logaddexp.reduce(raw))  # log Σ_z of the unnormalised prior
        self.log_w = raw - self.log_norm
        self.log_evidence = 0.0  # log Π_k P(h_k), the normalisers so far

    @property
    def weights(self) -> np.ndarray:
        return np.exp(self.log_w - np.logaddexp.reduce(self.log_w))

    def entropy_bits(self) -> float:
        w = self.weights
        return float(-(w * np.log2(np.clip(w, 1e-300, None))).sum())

    def top(self, n: int = 1) -> list[tuple[Hypothesis, float]]:
        w = self.weights
        return [(self.hyps[i], float(w[i])) for i in ranking.order(w, ranking.WEIGHT_DECIMALS)[:n]]

    def update(self, likelihood: np.ndarray) -> float:
        """Bayes' rule w_z ← w_z P(h | z) / P(h); returns P(h) = Σ_z w_z P(h | z)."""
        evidence = float(self.weights @ likelihood)
        self.log_w = self.log_w + np.log(np.clip(likelihood, 1e-300, None))
        norm = np.logaddexp.reduce(self.log_w)
        self.log_w -= norm
        self.log_evidence += math.log(max(evidence, 1e-300))
        return evidence

    def add(self, new: list[Hypothesis], mass: float, log_lik: np.ndarray) -> None:
        """Add hypotheses sharing prior ``mass``, scored by ``log_lik`` (their Σ_k log P(h_k | z)):
        the old posterior is put back on the joint scale (× P(h_1..k)) before renormalising."""
        each = math.log(mass / len(new))
        old = self.log_w + math.log(1 - mass) + self.log_evidence
        self.hyps = self.hyps + tuple(new)
        self.log_w = np.concatenate([old, each + log_lik])
        self.log_w -= np.logaddexp.reduce(self.log_w)

    def extend(self, new: tuple[Hypothesis, ...], log_lik: np.ndarray) -> None:
        """Add hypotheses with their own prior (same principle, same scale as the others) and
        their Σ_k log P(h_k | z): the posterior is then exactly the one over the larger space,
        as if the new z had been enumerated from the start."""
        if not new:
            return
        raw_new = raw_log_prior(new, self.prior)
        joint = np.concatenate([self.log_w + self.log_evidence + self.log_norm, raw_new + log_lik])
        self.hyps = self.hyps + tuple(new)
        self.log_norm = float(np.logaddexp(self.log_norm, np.logaddexp.reduce(raw_new)))
        total = float(np.logaddexp.reduce(joint))
        self.log_w = joint - total
        self.log_evidence = total - self.log_norm
