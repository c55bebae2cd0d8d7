"""Likelihoods of the user's answers: the preference family and the stop model's edge cases."""

from __future__ import annotations

import numpy as np
import pytest

from activeintent.learners.bayes.likelihood import (
    PreferenceModel,
    StopModel,
    preference_probs,
    stop_likelihood,
    stop_outcome_probs,
)
from activeintent.users.preference_model import preference_probabilities


@pytest.mark.parametrize("ua,ub,sim", [(1.0, 0.3, 0.0), (0.5, 0.5, 1.0), (0.2, 0.9, 0.4), (0.6, 0.58, 0.9)])
def test_preference_is_the_users_family_plus_lapse(ua, ub, sim):
    m = PreferenceModel(beta=7.0, indifference=0.1, confusion=2.0, lapse=0.0)
    mine = preference_probs(np.array([ua]), np.array([ub]), sim, m)[0]
    theirs = preference_probabilities(ua, ub, sim, beta=7.0, indifference=0.1, confusion=2.0)
    assert mine == pytest.approx([theirs["A"], theirs["B"], theirs["cant_choose"]])
    lapsed = preference_probs(np.array([ua]), np.array([ub]), sim, PreferenceModel(lapse=0.03))[0]
    assert lapsed.sum() == pytest.approx(1.0) and lapsed.min() >= 0.01


# Three hypotheses: z0 moves away at step 0, z1 at step 2, z2 never.
AWAY = np.array([0, 2, -1])
START = np.array([0.0, 3.0, 6.0])
REVEAL = START + 1.0
DURATION = 9.0
M = StopModel()


def test_no_stop_favours_the_hypothesis_with_nothing_wrong():
    lik = stop_likelihood(None, AWAY, REVEAL, START, DURATION, M)
    assert lik[2] > 10 * lik[0] and lik[2] > 10 * lik[1]
    assert lik.min() > 0


def test_timely_stop_picks_the_step_that_moved_away():
    t = REVEAL[2] + M.delay_mean
    lik = stop_likelihood(t, AWAY, REVEAL, START, DURATION, M)
    assert np.argmax(lik) == 1
    t0 = REVEAL[0] + M.delay_mean
    assert np.argmax(stop_likelihood(t0, AWAY, REVEAL, START, DURATION, M)) == 0


def test_early_stop_before_any_violation_is_a_false_stop_not_a_zero():
    # a stop at 0.2 s: before anything was revealed; no hypothesis predicts it
    lik = stop_likelihood(0.2, AWAY, REVEAL, START, DURATION, M)
    assert lik.min() > 0
    assert lik.max() / lik.min() < 5  # weak evidence only


def test_late_stop_still_points_at_the_offending_step_and_never_zeroes():
    # a stop 2.5 s after step 2 revealed, clipped at the end of τ
    lik = stop_likelihood(DURATION, AWAY, REVEAL, START, DURATION, M)
    assert lik.min() > 0
    assert np.argmax(lik) == 1  # only z1 had something go wrong late
    # far beyond anything: every hypothesis gets the lapse/false-stop floor, none zero
    lik = stop_likelihood(100.0, AWAY, REVEAL, START, DURATION, M)
    assert lik.min() > 0


def test_discretised_stop_outcomes_sum_to_one():
    p = stop_outcome_probs(AWAY, 3, M)
    assert p.shape == (3, 4)
    assert p.sum(axis=1) == pytest.approx(1.0)
    assert np.argmax(p[0]) == 0 and np.argmax(p[1]) == 2 and np.argmax(p[2]) == 3
