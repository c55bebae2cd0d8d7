"""A belief over reward weights w on the unit sphere, as weighted particles.

Prior ``uniform``: uniform on the sphere (normalised standard normals; APReL's choice). After
each answer the particles are reweighted by P(h | w), resampled (systematic) when the effective
sample size falls below half, and moved by Metropolis–Hastings steps that leave the
posterior invariant: w' = normalise(w + s/√d · ε), symmetric on the sphere, accepted with
min(1, P(h_1..k | w') / P(h_1..k | w)).

Prior ``heavy-tailed``: w = x / ‖x‖ with x_i independent standard Cauchy — a reward that
weighs a few features heavily is a priori as likely as one that weighs all a little (the
principle: few features, short description). The particles keep x; a move is a symmetric
random walk x' = x + s · m · ε (m: the median |x| over every particle and feature, fixed for the
move) accepted with the prior ratio ∏ (1 + x_i²) / (1 + x_i'²) times the likelihood ratio.

Every draw comes from the learner's generator; log-likelihood differences are quantised before
the accept test (``ranking``) so that float noise cannot flip a choice.
"""

from __future__ import annotations

import math

import numpy as np

from activeintent import ranking
from activeintent.learners.reward.models import RewardModel, RewardObservation

STEP_SCALES = (1.0, 0.3, 0.1)  # s: proposal sizes, cycled (large moves first)
PRIORS = ("uniform", "heavy-tailed")


def _normalise(W: np.ndarray) -> np.ndarray:
    return W / np.linalg.norm(W, axis=-1, keepdims=True)


class RewardBelief:
    def __init__(self, d: int, rng: np.random.Generator, model: RewardModel, n: int = 512, moves: int = 24,
                 prior: str = "uniform"):
        if prior not in PRIORS:
            raise ValueError(f"unknown reward prior {prior!r}; valid priors: {', '.join(PRIORS)}")
        self.d, self.rng, self.model, self.moves = d, rng, model, moves
        self.X = rng.standard_cauchy((n, d)) if prior == "heavy-tailed" else None
        self.W = _normalise(rng.standard_normal((n, d)) if self.X is None else self.X)
        self.log_w = np.zeros(n)
        self.log_evidence = 0.0  # log Π_k P(h_k | h_<k): the marginal likelihood, estimated by the particles
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
        self.log_evidence += math.log(max(evidence, 1e-300))
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
        if self.X is not None:
            self.X = self.X[idx]
        self.log_w = np.zeros(n)

    def _move(self) -> None:
        if not self.moves:  # no moves, no acceptance rate
            return
        if self.X is not None:
            self._move_heavy_tailed()
            return
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

    def _move_heavy_tailed(self) -> None:
        X = self.X
        assert X is not None
        cur = self.log_lik(self.W) - np.log1p(X**2).sum(axis=1)
        m = float(np.median(np.abs(X)))
        accepted = 0
        for k in range(self.moves):
            scale = STEP_SCALES[k % len(STEP_SCALES)] * m
            prop = X + scale * self.rng.standard_normal(X.shape)
            new = self.log_lik(_normalise(prop)) - np.log1p(prop**2).sum(axis=1)
            u = self.rng.random(len(X))
            ok = ranking.quantised(np.log(np.maximum(u, 1e-300))) < ranking.quantised(new - cur)
            X = np.where(ok[:, None], prop, X)
            cur = np.where(ok, new, cur)
            accepted += int(ok.sum())
        self.X, self.W = X, _normalise(X)
        self.accept.append(accepted / (self.moves * len(X)))
