"""A belief over reward weights w on the unit sphere, as weighted particles.

Prior: uniform on the sphere (normalised standard normals; APReL's choice). After each
answer the particles are reweighted by P(h | w), resampled (systematic) when the effective
sample size falls below half, and moved by Metropolis–Hastings steps that leave the
posterior invariant: w' = normalise(w + s/√d · ε), symmetric on the sphere, accepted with
min(1, P(h_1..k | w') / P(h_1..k | w)). Every draw comes from the learner's generator;
log-likelihood differences are quantised before the accept test (``ranking``) so that float
noise cannot flip a choice.
"""

from __future__ import annotations

import numpy as np

from activeintent import ranking
from activeintent.learners.reward.models import RewardModel, RewardObservation

STEP_SCALES = (1.0, 0.3, 0.1)  # s: proposal sizes, cycled (large moves first)


def _normalise(W: np.ndarray) -> np.ndarray:
    return W / np.linalg.norm(W, axis=-1, keepdims=True)


class RewardBelief:
    def __init__(self, d: int, rng: np.random.Generator, model: RewardModel, n: int = 512, moves: int = 24):
        self.d, self.rng, self.model, self.moves = d, rng, model, moves
        self.W = _normalise(rng.standard_normal((n, d)))
        self.log_w = np.zeros(n)
        self.obs: list[RewardObservation] = []
        self.accept: list[float] = []

    @property
    def weights(self) -> np.ndarray:
        w = np.exp(self.log_w - self.log_w.max())
        return w / w.sum()

    def ess(self) -> float:
        w = self.weights
        return float(1 / (w @ w))

    def mean(self) -> np.ndarray:
        """E[w] (not renormalised: its length says how much the particles agree)."""
        return self.weights @ self.W

    def direction(self) -> np.ndarray:
        m = self.mean()
        n = float(np.linalg.norm(m))
        return m / n if n > 0 else m

    def log_lik(self, W: np.ndarray) -> np.ndarray:
        total = np.zeros(len(W))
        for o in self.obs:
            total += o.log_lik(W, self.model)
        return total

    def update(self, obs: RewardObservation) -> float:
        """Bayes' rule on the particles; returns the evidence P(h) under the belief before."""
        lik = obs.log_lik(self.W, self.model)
        evidence = float(self.weights @ np.exp(lik))
        self.obs.append(obs)
        self.log_w = self.log_w + lik
        self.log_w -= self.log_w.max()
        if self.ess() < len(self.W) / 2:
            self._resample()
        self._move()
        return evidence

    def _resample(self) -> None:
        n = len(self.W)
        c = np.cumsum(ranking.quantised(self.weights, ranking.WEIGHT_DECIMALS))
        u = (self.rng.random() + np.arange(n)) / n * c[-1]
        idx = np.minimum(np.searchsorted(c, u, side="right"), n - 1)
        self.W = self.W[idx]
        self.log_w = np.zeros(n)

    def _move(self) -> None:
        cur = self.log_lik(self.W)
        accepted = 0
        for k in range(self.moves):
            s = STEP_SCALES[k % len(STEP_SCALES)] / np.sqrt(self.d)
            prop = _normalise(self.W + s * self.rng.standard_normal(self.W.shape))
            new = self.log_lik(prop)
            u = self.rng.random(len(self.W))
            ok = ranking.quantised(np.log(np.maximum(u, 1e-300))) < ranking.quantised(new - cur)
            self.W = np.where(ok[:, None], prop, self.W)
            cur = np.where(ok, new, cur)
            accepted += int(ok.sum())
        self.accept.append(accepted / (self.moves * len(self.W)))
