"""The reward learners' observation models P(h | w) for linear rewards r(s) = w · φ(s),
evaluated for many w at once (W: [M, d], one particle a row).

- **Preference** (A / B / can't choose) — a weak comparison (Bıyık et al. 2019, "asking easy
  questions") with lapses: with d = β (r_A − r_B) and threshold δ' = β δ,
  P(A) = σ(d − δ'), P(B) = σ(−d − δ'), P(can't choose) = 1 − P(A) − P(B); then
  (1 − λ) P + λ / 3.
- **Stop** — a reward-rational implicit choice (Jeon, Milli & Dragan 2020) among the plan's
  prefixes: stopping during step j keeps the state before step j, i.e. chooses prefix j;
  watching to the end chooses the whole plan (prefix n). P(j | w) = softmax_j(β r(prefix j)),
  with lapse λ / (n + 1). The press time t says which step the person reacted to only up to
  a reaction delay: the step is a mixture π_j(t) ∝ lognormal delay density of t − (reveal_j),
  over steps revealed before t (the step under way if none).
- **New scene** — the person says the scene cannot show what they want when nothing the
  robot can do here raises their reward: with g(w) = max_c w · (φ(s_c) − φ(s_0)) over the
  learner's candidate outcomes of the scene (so, which features the scene can change),
  P(new scene | w) = ε + (1 − 2ε) σ(β_ns (δ_ns − g(w))); every other answer carries
  1 − P(new scene | w).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from pydantic import BaseModel, Field


class RewardModel(BaseModel):
    """What the reward learners assume of people (no simulated user's parameter)."""

    # With w on the unit sphere one block changing one relation changes r by ~0.1–0.5, so β = 10
    # makes a clear change a confident (≈ 99 %) choice and a small one close to a coin flip.
    beta: float = Field(10.0, gt=0, description="β: rationality on reward differences (w on the unit sphere)")
    weak: float = Field(0.1, ge=0, description="δ: reward differences below this are hard to choose between")
    lapse: float = Field(0.05, ge=0, lt=1, description="λ: a uniformly random answer")
    stop_beta: float = Field(10.0, gt=0, description="β of the choice among prefixes")
    stop_lapse: float = Field(0.05, ge=0, lt=1)
    delay_mean: float = Field(0.9, gt=0, description="s, reaction delay after a step's destination shows")
    delay_sd: float = Field(0.6, gt=0)
    new_scene_error: float = Field(0.1, gt=0, lt=0.5, description="ε: a new-scene answer (or its absence) is wrong")
    new_scene_beta: float = Field(20.0, gt=0)
    new_scene_margin: float = Field(0.05, ge=0, description="δ_ns: the gain below which a scene shows nothing")


def assumed(model: RewardModel, signal_model: BaseModel) -> RewardModel:
    """``model`` with what the signal's learner model assumes of people: the preference lapse;
    for stops the reaction delay and, as the prefix choice's lapse, every way a stop says
    nothing about the reward (false stops, missed stops, lapses)."""
    m = signal_model
    if hasattr(m, "delay_mean"):
        return model.model_copy(update={"delay_mean": m.delay_mean, "delay_sd": m.delay_sd,
                                        "stop_lapse": min(0.5, m.false_stop + m.missed_stop + m.lapse)})
    return model.model_copy(update={"lapse": m.lapse})


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 0.5 * (1 + np.tanh(0.5 * x))


def preference_probs(r_a: np.ndarray, r_b: np.ndarray, m: RewardModel) -> np.ndarray:
    """[..., 3]: P(A), P(B), P(can't choose)."""
    d = m.beta * (np.asarray(r_a) - np.asarray(r_b))
    t = m.beta * m.weak
    pa, pb = _sigmoid(d - t), _sigmoid(-d - t)
    p = np.stack([pa, pb, np.clip(1 - pa - pb, 0.0, 1.0)], -1)
    return (1 - m.lapse) * p + m.lapse / 3


def prefix_probs(R: np.ndarray, m: RewardModel) -> np.ndarray:
    """[M, n + 1] P(prefix j) from prefix rewards R [M, n + 1]."""
    z = m.stop_beta * R
    z = z - z.max(axis=-1, keepdims=True)
    p = np.exp(z)
    p /= p.sum(axis=-1, keepdims=True)
    return (1 - m.stop_lapse) * p + m.stop_lapse / R.shape[-1]


def p_new_scene(W: np.ndarray, gains: np.ndarray, m: RewardModel) -> np.ndarray:
    """[M] P(new scene | w) for a scene whose candidate outcomes change φ by ``gains`` [C, d]."""
    if not len(gains):
        return np.full(len(W), 1 - m.new_scene_error)
    g = (W @ gains.T).max(axis=1)
    e = m.new_scene_error
    return e + (1 - 2 * e) * _sigmoid(m.new_scene_beta * (m.new_scene_margin - g))


def lognormal_density(x: np.ndarray, mean: float, sd: float) -> np.ndarray:
    s2 = math.log(1 + (sd / mean) ** 2)
    mu = math.log(mean) - s2 / 2
    xp = np.maximum(x, 1e-9)
    return np.where(x > 0, np.exp(-((np.log(xp) - mu) ** 2) / (2 * s2)) / (xp * math.sqrt(2 * math.pi * s2)), 0.0)


def stop_step_weights(t: float, reveal: np.ndarray, start: np.ndarray, m: RewardModel) -> np.ndarray:
    """π_j(t): which step a press at t reacted to (sums to 1 over the steps)."""
    dens = lognormal_density(t - reveal, m.delay_mean, m.delay_sd)
    if dens.sum() <= 0:
        under = np.flatnonzero(start <= t)
        dens = np.zeros(len(reveal))
        dens[under[-1] if len(under) else 0] = 1.0
    return dens / dens.sum()


@dataclass
class RewardObservation:
    """One answer as the belief needs it: the φ vectors it compares and the answer."""

    kind: str  # "preference" | "stop" | "new_scene"
    vectors: np.ndarray  # [k, d]: preference (φ_A, φ_B); stop: φ of prefixes 0..n
    gains: np.ndarray  # [C, d]: what the scene's candidates change (new-scene model)
    choice: int = 0  # preference: 0 A, 1 B, 2 can't choose
    mix: np.ndarray = field(default_factory=lambda: np.zeros(0))  # stop: P(prefix j) from the time

    def log_lik(self, W: np.ndarray, m: RewardModel) -> np.ndarray:
        pns = p_new_scene(W, self.gains, m)
        if self.kind == "new_scene":
            return np.log(pns)
        R = W @ self.vectors.T
        if self.kind == "preference":
            p = preference_probs(R[:, 0], R[:, 1], m)[:, self.choice]
        else:
            p = prefix_probs(R, m) @ self.mix
        return np.log(np.clip(p, 1e-300, None)) + np.log1p(-pns)
