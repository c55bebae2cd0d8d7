"""The belief (belief.py) and acquisition (acquisition.py) of the Bayesian learners on
hand-computed cases: priors, Bayes' rule, hypotheses added later, information gain, and the
query chosen for a belief split between two hypotheses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from activeintent.envs.symbolic import symbolic_trajectory
from activeintent.goals.facts import facts
from activeintent.learners.bayes.acquisition import eig, select_query, with_new_scene
from activeintent.learners.bayes.belief import Belief, log_prior
from activeintent.learners.bayes.candidates import candidate_plans
from activeintent.learners.bayes.hypotheses import hypothesis_space
from activeintent.learners.bayes.judge import HypothesisJudge
from activeintent.signals import get_signal
from activeintent.world import PutIn, Scene, WorldState, layout

BY_NAME = {h.name: h for h in hypothesis_space()}


def hyps(*names: str) -> tuple:
    return tuple(BY_NAME[n] for n in names)


# Judges memoise verdicts per hypothesis tuple: keep every tuple a test judges with alive.
SAME_OTHER = hyps("all:in-same-bowl", "all:in-other-bowl")
THREE = hyps("all:in-same-bowl", "all:tower", "all:row")
FOUR = hyps("all:in-same-bowl", "all:tower", "all:row", "all:one-bowl")


def belief(h: tuple, weights: list[float]) -> Belief:
    b = Belief(h, prior="uniform")
    b.log_w = np.log(np.array(weights))
    return b


def test_length_prior_is_two_to_the_minus_description_length():
    h = FOUR
    p = np.exp(log_prior(h, "length"))
    bits = np.array([x.bits for x in h])
    assert p.sum() == pytest.approx(1.0)
    assert p == pytest.approx(2.0**-bits / (2.0**-bits).sum())
    assert np.exp(log_prior(h, "uniform")) == pytest.approx([0.25] * 4)
    with pytest.raises(ValueError, match="valid priors: length, uniform"):
        log_prior(h, "flat")  # type: ignore[arg-type]
    # the full space: simpler hypotheses are more probable a priori
    space = hypothesis_space()
    full = Belief(space)
    assert full.weights.sum() == pytest.approx(1.0)
    order = np.argsort([x.bits for x in space], kind="stable")
    assert np.all(np.diff(full.weights[order]) <= 1e-15)


def test_two_hypothesis_update_matches_hand_computation():
    b = belief(SAME_OTHER, [0.5, 0.5])
    # P(h | z1) = 0.8, P(h | z2) = 0.2  ->  posterior 0.8 / (0.8 + 0.2) = 0.8; P(h) = 0.5
    assert b.update(np.array([0.8, 0.2])) == pytest.approx(0.5)
    assert b.weights == pytest.approx([0.8, 0.2])
    # a second, independent answer with the same likelihoods: 0.64 / (0.64 + 0.04)
    assert b.update(np.array([0.8, 0.2])) == pytest.approx(0.68)
    assert b.weights == pytest.approx([0.64 / 0.68, 0.04 / 0.68])
    assert b.log_evidence == pytest.approx(math.log(0.5 * 0.68))


def test_three_hypothesis_update_with_unequal_prior():
    b = belief(THREE, [0.5, 0.3, 0.2])
    b.update(np.array([0.1, 0.6, 0.3]))
    unnorm = np.array([0.05, 0.18, 0.06])
    assert b.weights == pytest.approx(unnorm / unnorm.sum())
    assert b.top()[0][0].name == "all:tower"
    assert [x.name for x, _ in b.top(3)] == ["all:tower", "all:row", "all:in-same-bowl"]


def test_a_zero_likelihood_is_floored_not_fatal():
    b = belief(SAME_OTHER, [0.5, 0.5])
    b.update(np.array([1.0, 0.0]))
    assert np.isfinite(b.log_w).all() and b.weights == pytest.approx([1.0, 0.0])


def test_entropy_in_bits():
    assert belief(FOUR, [0.25] * 4).entropy_bits() == pytest.approx(2.0)
    assert belief(SAME_OTHER, [0.5, 0.5]).entropy_bits() == pytest.approx(1.0)
    assert belief(SAME_OTHER, [1 - 1e-12, 1e-12]).entropy_bits() == pytest.approx(0.0, abs=1e-9)


def test_added_hypotheses_are_scored_as_if_they_had_been_there_from_the_start():
    b = belief(SAME_OTHER, [0.5, 0.5])
    b.update(np.array([0.8, 0.2]))
    new = hyps("all:tower", "all:row")
    # the newcomers get prior mass 0.1 (0.05 each); one agrees with the answer (0.8), one not (0.2)
    b.add(list(new), 0.1, np.log(np.array([0.8, 0.2])))
    # by hand: prior [0.45, 0.45, 0.05, 0.05] × likelihood [0.8, 0.2, 0.8, 0.2], normalised by 0.5
    assert [x.name for x in b.hyps] == ["all:in-same-bowl", "all:in-other-bowl", "all:tower", "all:row"]
    assert b.weights == pytest.approx([0.72, 0.18, 0.08, 0.02])
    # the same as a belief that held all four from the start
    ref = belief(b.hyps, [0.45, 0.45, 0.05, 0.05])
    ref.update(np.array([0.8, 0.2, 0.8, 0.2]))
    assert b.weights == pytest.approx(ref.weights)


def test_information_gain_prefers_a_splitting_query():
    w = np.array([0.5, 0.5])
    # query 1: both hypotheses predict the same answer -> no information
    same = np.array([[0.9, 0.05, 0.05], [0.9, 0.05, 0.05]])
    # query 2: z1 answers A, z2 answers B
    split = np.array([[0.9, 0.05, 0.05], [0.05, 0.9, 0.05]])
    assert eig(w, same) == pytest.approx(0.0, abs=1e-12)
    # by hand: H[0.475, 0.475, 0.05] − H[0.9, 0.05, 0.05]
    h_marginal = -(2 * 0.475 * math.log(0.475) + 0.05 * math.log(0.05))
    h_each = -(0.9 * math.log(0.9) + 2 * 0.05 * math.log(0.05))
    assert eig(w, split) == pytest.approx(h_marginal - h_each)
    assert eig(w, split) > eig(w, same)
    # a perfect split of two equally likely hypotheses is worth exactly one bit
    assert eig(w, np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])) == pytest.approx(math.log(2))
    # ... and nothing once the belief is certain
    assert eig(np.array([1.0, 0.0]), split) == pytest.approx(0.0, abs=1e-12)


def test_new_scene_answer_is_appended_to_the_predictive():
    p = np.array([[0.7, 0.3], [0.2, 0.8]])
    out = with_new_scene(p, np.array([True, False]), 0.1)
    assert out.shape == (2, 3) and out.sum(axis=1) == pytest.approx(1.0)
    assert out[0] == pytest.approx([0.63, 0.27, 0.1])  # showable: new scene only by mistake
    assert out[1] == pytest.approx([0.02, 0.08, 0.9])  # not showable: new scene is the answer
    # a scene that shows one hypothesis but not the other is itself informative
    assert eig(np.array([0.5, 0.5]), out) > eig(np.array([0.5, 0.5]), p)


SCENE = Scene(objects=["red block", "blue block", "red bowl", "blue bowl"])


@pytest.mark.parametrize("signal", ["preference", "stop"])
def test_the_chosen_query_splits_a_belief_between_two_hypotheses(signal):
    """With the belief split between "own-colour bowl" and "other bowl", the query chosen by
    expected information gain shows outcomes the two hypotheses judge differently."""
    sig = get_signal(signal)
    w = np.array([0.5, 0.5])
    state = WorldState(positions=layout(SCENE, 3))
    rng = np.random.default_rng(0)
    outs = candidate_plans(SAME_OTHER, w, state, rng, prefixes=sig.shows > 1)
    assert len(outs) >= 2
    judge = HypothesisJudge(SAME_OTHER)
    q = select_query(sig, sig.learner_model(), judge, w, np.array([True, True]), outs, 0.1, rng)
    assert q is not None and len(q.plans) == sig.shows and q.gain > 0.3
    trajs = [symbolic_trajectory(SCENE, state, p) for p in q.plans]
    if signal == "preference":
        sats = [[h.holds_f(facts(t.outcome)) for h in SAME_OTHER] for t in trajs]
        assert sats[0] != sats[1]
    else:
        away = judge.first_away(trajs[0])
        assert away[0] != away[1]
    # the random baseline picks from the same candidates, without computing a gain
    r = select_query(sig, sig.learner_model(), judge, w, np.array([True, True]), outs, 0.1, rng, choose="random")
    assert r is not None and math.isnan(r.gain)
    assert all(any(o is c for c in outs) for o in r.outcomes)


def test_no_query_without_distinct_candidates():
    sig = get_signal("preference")
    state = WorldState(positions=layout(SCENE, 3))
    one = candidate_plans(SAME_OTHER, np.array([0.5, 0.5]), state, np.random.default_rng(0))[:1]
    q = select_query(sig, sig.learner_model(), HypothesisJudge(SAME_OTHER), np.array([0.5, 0.5]),
                     np.array([True, True]), one, 0.1, np.random.default_rng(0))
    assert q is None
    # doing nothing is never a candidate: every candidate moves something
    outs = candidate_plans(SAME_OTHER, np.array([0.5, 0.5]), state, np.random.default_rng(0))
    assert all(o.plan for o in outs)


def test_judges_of_different_hypothesis_tuples_do_not_share_verdicts():
    state = WorldState(positions=layout(SCENE, 0))
    end = symbolic_trajectory(SCENE, state, [PutIn(block="red block", bowl="red bowl"),
                                             PutIn(block="blue block", bowl="blue bowl")]).outcome
    same, other = BY_NAME["all:in-same-bowl"], BY_NAME["all:in-other-bowl"]
    for _ in range(5):
        first = HypothesisJudge(tuple([same, other]))  # a fresh tuple, freed below
        assert first.utility(end) == pytest.approx([1.0, 0.0])
        del first
        second = HypothesisJudge(tuple([other, same]))
        assert second.utility(end) == pytest.approx([0.0, 1.0])
