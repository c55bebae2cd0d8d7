"""Bayes' rule and information gain on hand-computed cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from activeintent.learners.bayes.hypotheses import hypothesis_space
from activeintent.learners.bayes.learner import BayesPreferenceLearner
from activeintent.learners.bayes.likelihood import PreferenceModel
from activeintent.learners.bayes.query import eig


def _learner(names: list[str], prior: list[float]) -> BayesPreferenceLearner:
    by_name = {h.name: h for h in hypothesis_space()}
    learner = BayesPreferenceLearner(rng=0, hypotheses=tuple(by_name[n] for n in names))
    learner.log_w = np.log(np.array(prior))
    return learner


def test_two_hypothesis_update_matches_hand_computation():
    learner = _learner(["all:in-same-bowl", "all:tower"], [0.5, 0.5])
    # P(h | z1) = 0.8, P(h | z2) = 0.2  ->  posterior 0.8 / (0.8 + 0.2) = 0.8
    learner.update(np.array([0.8, 0.2]))
    assert learner.weights == pytest.approx([0.8, 0.2])
    # a second, independent answer with the same likelihoods: 0.64 / (0.64 + 0.04)
    learner.update(np.array([0.8, 0.2]))
    assert learner.weights == pytest.approx([0.64 / 0.68, 0.04 / 0.68])


def test_three_hypothesis_update_with_unequal_prior():
    learner = _learner(["all:in-same-bowl", "all:tower", "all:row"], [0.5, 0.3, 0.2])
    lik = np.array([0.1, 0.6, 0.3])
    learner.update(lik)
    unnorm = np.array([0.05, 0.18, 0.06])
    assert learner.weights == pytest.approx(unnorm / unnorm.sum())
    assert learner.top()[0][0].name == "all:tower"


def test_information_gain_prefers_a_splitting_query():
    w = np.array([0.5, 0.5])
    # query 1: both hypotheses predict the same answer -> no information
    same = np.array([[[0.9, 0.05, 0.05], [0.9, 0.05, 0.05]]])
    # query 2: z1 answers A, z2 answers B
    split = np.array([[[0.9, 0.05, 0.05], [0.05, 0.9, 0.05]]])
    gains = eig(w, np.concatenate([same, split]))
    assert gains[0] == pytest.approx(0.0, abs=1e-12)
    # by hand: H[0.475, 0.475, 0.05] − H[0.9, 0.05, 0.05]
    h_marginal = -(2 * 0.475 * math.log(0.475) + 0.05 * math.log(0.05))
    h_each = -(0.9 * math.log(0.9) + 2 * 0.05 * math.log(0.05))
    assert gains[1] == pytest.approx(h_marginal - h_each)
    assert gains[1] > gains[0]
    # a perfect split of two equally likely hypotheses is worth exactly one bit
    perfect = np.array([[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    assert eig(w, perfect)[0] == pytest.approx(math.log(2))


def test_learner_query_splits_its_belief():
    """The chosen pair separates the two live hypotheses: one plan satisfies only z1."""
    from activeintent.learners.bayes.facts import facts
    from activeintent.learners.bayes.query import (
        best_preference_query,
        candidate_plans,
        scene_state,
    )
    from activeintent.world import Scene

    learner = _learner(["all:in-same-bowl", "all:in-other-bowl"], [0.5, 0.5])
    state = scene_state(Scene(objects=["red block", "blue block", "red bowl", "blue bowl"]), 3)
    outs = candidate_plans(learner.hyps, learner.weights, state, learner.rng)
    q = best_preference_query(learner.hyps, learner.weights, state, outs, PreferenceModel())
    assert q is not None and q.gain > 0.3
    from activeintent.world import apply_plan

    sats = [[h.holds_f(facts(apply_plan(state, p)[0][-1])) for h in learner.hyps] for p in q.plans]
    assert sats[0] != sats[1]
