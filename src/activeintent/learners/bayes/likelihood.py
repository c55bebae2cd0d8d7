"""P(h | z): how likely each hypothesis makes the user's signal h, vectorised over hypotheses.

Preference: the same family as the simulated preference user (users/preference_model.py):
utility u = (score + 1[satisfied]) / 2, Boltzmann-rational over {A, B, cant_choose} with an
indifference margin and a similarity confusion — with the learner's own parameters, mixed
with a small lapse rate so that no single answer can rule every hypothesis out.

Stop: under z the user stops after the first step that moves away from z, at the time that
step reveals its destination plus a reaction delay (normal, with a late tail); false stops
(anywhere) and missed stops have their own mass, and a lapse rate mixes in a uniform answer.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, Field

CHOICES = ("A", "B", "cant_choose")


class PreferenceModel(BaseModel):
    """The learner's model of a preference user (not the user's true parameters)."""

    beta: float = Field(12.0, gt=0, description="rationality on utility differences")
    indifference: float = Field(0.05, ge=0, description="utility margin below which a choice is not worth it")
    confusion: float = Field(1.0, ge=0, description="log-odds added to cant_choose for identical outcomes")
    lapse: float = Field(0.03, ge=0, lt=1, description="probability of a uniformly random answer")


class StopModel(BaseModel):
    """The learner's model of a stop user."""

    delay_mean: float = Field(0.5, description="s after the step reveals its destination")
    delay_sd: float = Field(0.3, gt=0)
    late_tail: float = Field(0.1, ge=0, le=1, description="share of stops anywhere after the reveal")
    false_stop: float = Field(0.05, ge=0, lt=1, description="P(stop although nothing moved away)")
    missed_stop: float = Field(0.05, ge=0, lt=1, description="P(no stop although a step moved away)")
    lapse: float = Field(0.02, ge=0, lt=1)


def utility(score: np.ndarray, sat: np.ndarray) -> np.ndarray:
    """u = (score + 1[satisfied]) / 2 ∈ [0, 1], elementwise."""
    return 0.5 * (np.clip(score, 0.0, 1.0) + sat.astype(float))


def preference_probs(
    u_a: np.ndarray, u_b: np.ndarray, similarity: np.ndarray | float, m: PreferenceModel
) -> np.ndarray:
    """P(h ∈ (A, B, cant_choose)) for every entry of u_a, u_b (broadcast); shape (..., 3)."""
    d = np.asarray(u_a, float) - np.asarray(u_b, float)
    sim = np.clip(np.broadcast_to(np.asarray(similarity, float), d.shape), 0.0, 1.0)
    logits = np.stack(
        [m.beta * d / 2, -m.beta * d / 2, m.beta * (m.indifference - np.abs(d) / 2) + m.confusion * sim],
        axis=-1,
    )
    logits -= logits.max(axis=-1, keepdims=True)
    p = np.exp(logits)
    p /= p.sum(axis=-1, keepdims=True)
    return (1 - m.lapse) * p + m.lapse / 3


def preference_likelihood(
    choice: str, u_a: np.ndarray, u_b: np.ndarray, similarity: float, m: PreferenceModel
) -> np.ndarray:
    """P(choice | z) for every hypothesis z (arrays of utilities of the two outcomes)."""
    if choice not in CHOICES:
        raise ValueError(f"unknown preference answer {choice!r}; valid: {', '.join(CHOICES)}")
    return preference_probs(u_a, u_b, similarity, m)[..., CHOICES.index(choice)]


def _normal(t: float, mu: np.ndarray, sd: float) -> np.ndarray:
    return np.exp(-0.5 * ((t - mu) / sd) ** 2) / (sd * math.sqrt(2 * math.pi))


def stop_likelihood(
    stop_time: float | None,
    away_step: np.ndarray,
    reveal: np.ndarray,
    start: np.ndarray,
    duration: float,
    m: StopModel,
) -> np.ndarray:
    """P(h | z) for every z, given the index of z's first step that moves away (-1: none).

    ``reveal``/``start`` give each step's reveal and start time (s); ``duration`` the length
    of τ. For a stop at t the value is a density in 1/s, for "no stop" a probability; both
    are compared only across hypotheses, which is all Bayes' rule needs.
    """
    away_step = np.asarray(away_step)
    has = away_step >= 0
    span = max(duration, 1e-3) + m.delay_mean + 3 * m.delay_sd  # stops may land after the end
    if stop_time is None:
        base = np.where(has, m.missed_stop, 1 - m.false_stop)
        return (1 - m.lapse) * base + m.lapse / 2
    k = np.where(has, away_step, 0)
    r = np.asarray(reveal, float)[k] if len(reveal) else np.zeros_like(k, dtype=float)
    s = np.asarray(start, float)[k] if len(start) else np.zeros_like(k, dtype=float)
    timely = _normal(stop_time, r + m.delay_mean, m.delay_sd)
    tail = np.where(stop_time >= s, 1.0 / np.maximum(span - s, 1e-3), 0.0)
    caught = (1 - m.late_tail) * timely + m.late_tail * tail
    base = m.false_stop / span + np.where(has, (1 - m.false_stop - m.missed_stop) * caught, 0.0)
    return (1 - m.lapse) * base + m.lapse / (2 * span)


def stop_outcome_probs(away_step: np.ndarray, n_steps: int, m: StopModel) -> np.ndarray:
    """Discretised outcome for query selection: P(stop during step j) for j < n, P(no stop) last.

    Shape (len(away_step), n_steps + 1). A stop is attributed to the step that moved away.
    """
    away_step = np.asarray(away_step)
    n = max(n_steps, 1)
    p = np.zeros((len(away_step), n + 1))
    has = away_step >= 0
    p[:, :n] = m.false_stop / n
    p[has, away_step[has]] += 1 - m.false_stop - m.missed_stop
    p[has, n] += m.missed_stop
    p[~has, n] += 1 - m.false_stop
    return (1 - m.lapse) * p + m.lapse / (n + 1)
