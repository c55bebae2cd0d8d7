"""The signals' observation models (signals/): the preference choice model and the stop model.

Users sample from these models and learners evaluate them, so the tests check the numbers
themselves (closed forms, normalisation, edge cases) and what one answer does to a belief:
a hypothesis that predicts the answer gains weight, one that it contradicts loses weight, and
one noisy answer never wipes out a hypothesis.

(Ported from tests/learners/test_bayes_likelihood.py; the utility/similarity and choice
probability checks come from tests/users/test_preference_user.py.)
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from activeintent.envs.symbolic import symbolic_trajectory
from activeintent.intentions import get_intention
from activeintent.learners.bayes.belief import Belief
from activeintent.learners.bayes.hypotheses import hypothesis_space
from activeintent.learners.bayes.judge import HypothesisJudge
from activeintent.signals import SIGNALS, get_signal
from activeintent.signals.preference import (
    CHOICES,
    PreferenceAnswer,
    PreferenceModel,
    choice_probabilities,
    similarity,
)
from activeintent.signals.stop import EXPORT_FPS, StopAnswer, StopModel
from activeintent.users.simulated import IntentionJudge
from activeintent.world import PutIn, PutNextTo, PutOn, Scene, WorldState, apply_plan, layout
from helpers import REVEAL, STEP_TICKS, kinematic_trajectory

PREF = get_signal("preference")
STOP = get_signal("stop")

# ---------------------------------------------------------------------------------------------
# registry and answers


def test_both_builtin_signals_are_registered_and_unknown_names_are_refused():
    assert {"preference", "stop"} <= set(SIGNALS.names())
    assert (PREF.shows, STOP.shows) == (2, 1)
    with pytest.raises(ValueError, match=r"valid signals: .*preference.*stop"):
        get_signal("clicker")


def test_new_scene_is_an_answer_of_every_signal():
    for sig in (PREF, STOP):
        h = sig.new_scene()
        assert h.new_scene and h.signal == sig.name
        assert "new scene" in h.describe()
    assert PREF.new_scene().choice is None and STOP.new_scene().stop_time is None


def test_an_answer_has_one_word_everywhere():
    """Answer.kind is the word records, reports and study exports use (one per answer kind)."""
    from activeintent.signals import answer_kind_from_dump

    pref, stop = get_signal("preference"), get_signal("stop")
    answers = {"A": pref.parse({"choice": "A"}), "cant_choose": pref.parse({"choice": "cant_choose"}),
               "stop": stop.parse({"stop_time": 1.5}), "no_stop": stop.parse({"stop_time": None}),
               "new_scene": stop.new_scene()}
    for word, answer in answers.items():
        assert answer.kind == word
        assert answer_kind_from_dump(answer.model_dump(mode="json")) == word
    assert answer_kind_from_dump({"signal": "rating", "stars": 4}) == "rating"  # a signal not registered here


def test_parse_refuses_unknown_fields_and_bad_values():
    assert STOP.parse({"stop_time": 1.5, "tick": 15}).stop_time == 1.5
    assert PREF.parse({"choice": "B"}).choice == "B"
    with pytest.raises(ValidationError):
        STOP.parse({"stop_time": 1.5, "step_index": 0})  # a person's stop is only a time
    with pytest.raises(ValidationError):
        STOP.parse({"stop_time": -0.1})
    with pytest.raises(ValidationError):
        PREF.parse({"choice": "C"})


# ---------------------------------------------------------------------------------------------
# preference: utility, similarity, the choice model

SCENE = Scene(objects=["red block", "blue block", "red bowl", "blue bowl"])
SEED = 3
MATCH = [PutIn(block="red block", bowl="red bowl"), PutIn(block="blue block", bowl="blue bowl")]
HALF = [PutIn(block="red block", bowl="red bowl")]
SWAP = [PutIn(block="red block", bowl="blue bowl"), PutIn(block="blue block", bowl="red bowl")]


def outcome(plan, scene: Scene = SCENE, seed: int = SEED) -> WorldState:
    state = WorldState(positions=layout(scene, seed))
    states, failures = apply_plan(state, plan)
    assert failures == [None] * len(plan)
    return states[-1] if states else state


def test_utility_and_similarity():
    judge = IntentionJudge(get_intention("color-match"))
    assert judge.utility(outcome(MATCH)) == pytest.approx([1.0])
    assert judge.utility(outcome(HALF)) == pytest.approx([0.25])  # (score 1/2 + not satisfied) / 2
    assert judge.utility(outcome(SWAP)) == pytest.approx([0.0])
    assert similarity(outcome(MATCH), outcome(MATCH)) == pytest.approx(1.0)
    assert similarity(outcome(MATCH), outcome(HALF)) < 1.0
    assert similarity(outcome(MATCH), outcome(SWAP)) < 0.01


def probs(ua, ub, sim, **kw) -> np.ndarray:
    kw.setdefault("lapse", 0.0)
    return choice_probabilities(np.array(ua), np.array(ub), sim, PreferenceModel(**kw))


def test_choice_probabilities_are_distributions():
    for ua, ub, sim, beta in [(0.9, 0.1, 0.0, 3.0), (0.5, 0.5, 0.8, 2.0), (0.2, 0.7, 0.3, 0.0), (1.0, 0.0, 1.0, 50.0)]:
        p = probs(ua, ub, sim, beta=beta)
        assert p.shape == (3,) and p.sum() == pytest.approx(1.0) and p.min() >= 0
    # broadcast over hypotheses: one row per pair of utilities
    many = probs([1.0, 0.0, 0.5], [0.0, 1.0, 0.5], 0.2, beta=8.0)
    assert many.shape == (3, 3) and many.sum(axis=1) == pytest.approx(1.0)
    assert many[0, 0] == pytest.approx(many[1, 1])  # swapping A and B swaps the answer


def test_choice_probabilities_limits_and_closed_form():
    # β = 0 without similarity: uniform; similarity raises "can't choose", whatever β.
    assert probs(1, 0, 0.0, beta=0.0) == pytest.approx([1 / 3] * 3)
    assert probs(0.6, 0.4, 0.9, beta=5.0)[2] > probs(0.6, 0.4, 0.0, beta=5.0)[2]
    # large β approaches the exact chooser; β = ∞ is exact; an exact tie is "can't choose"
    assert probs(0.6, 0.4, 0.5, beta=500.0)[0] > 0.99
    assert probs(0.6, 0.4, 0.5, beta=math.inf).tolist() == [1.0, 0.0, 0.0]
    assert probs(0.4, 0.6, 0.5, beta=math.inf).tolist() == [0.0, 1.0, 0.0]
    assert probs(0.4, 0.4, 0.0, beta=math.inf, indifference=0.0).tolist() == [0.0, 0.0, 1.0]
    assert probs(0.42, 0.4, 0.0, beta=math.inf, indifference=0.05).tolist() == [0.0, 0.0, 1.0]  # below m
    # closed form: P(C)/P(A) = exp(β(m − |d|/2) + κσ − βd/2), P(B)/P(A) = exp(−βd)
    p = probs(0.7, 0.3, 0.5, beta=4.0, indifference=0.05, confusion=2.0)
    assert p[2] / p[0] == pytest.approx(math.exp(4.0 * (0.05 - 0.2) + 2.0 * 0.5 - 4.0 * 0.2))
    assert p[1] / p[0] == pytest.approx(math.exp(-4.0 * 0.4))


@pytest.mark.parametrize("lapse", [0.03, 0.2])
def test_lapse_mixes_in_a_uniform_answer(lapse):
    for beta in (7.0, math.inf):
        clean = probs(1.0, 0.3, 0.1, beta=beta)
        lapsed = probs(1.0, 0.3, 0.1, beta=beta, lapse=lapse)
        assert lapsed == pytest.approx((1 - lapse) * clean + lapse / 3)
        assert lapsed.sum() == pytest.approx(1.0) and lapsed.min() >= lapse / 3 - 1e-12


def test_preference_likelihood_is_the_predictive_column_of_the_answer():
    hyps = HYPS[:3]
    judge = HypothesisJudge(hyps)
    shown = [symbolic_trajectory(SCENE, START, MATCH), symbolic_trajectory(SCENE, START, SWAP)]
    model = PREF.learner_model()
    table = PREF.predictive(shown, judge, model)
    assert table.shape == (3, 3) and table.sum(axis=1) == pytest.approx(1.0)
    for k, choice in enumerate(CHOICES):
        assert PREF.likelihood(PreferenceAnswer(choice=choice), shown, judge, model) == pytest.approx(table[:, k])
    with pytest.raises(ValueError, match="without a choice"):
        PREF.likelihood(PreferenceAnswer(), shown, judge, model)
    with pytest.raises(ValueError, match="two trajectories"):
        PREF.predictive(shown[:1], judge, model)


def test_preference_predictive_of_many_queries_is_each_querys_predictive_bit_for_bit():
    """select_query reads the predictive of hundreds of pairs at once (blocks of queries); its
    values must be exactly those of one query at a time, or the chosen queries would change."""
    from itertools import combinations

    from activeintent.signals.preference import PREDICTIVE_BLOCK

    judge = HypothesisJudge(HYPS)
    plans = [MATCH, HALF, SWAP, [], MATCH[:1], SWAP[:1], [PutOn(block="red block", target="blue block")]]
    outcomes = [symbolic_trajectory(SCENE, START, plan) for plan in plans]
    queries = [list(pair) for pair in combinations(outcomes, 2)] * 4  # more than one block
    assert len(queries) > PREDICTIVE_BLOCK
    for model in (PREF.learner_model(), PreferenceModel(beta=math.inf, lapse=0.0)):
        many = list(PREF.predictive_many(queries, judge, model))
        assert len(many) == len(queries)
        for shown, table in zip(queries, many, strict=True):
            assert np.array_equal(table, PREF.predictive(shown, judge, model))
    with pytest.raises(ValueError, match="two trajectories"):
        list(PREF.predictive_many([outcomes[:1]], judge, PREF.learner_model()))
    # the signals' default: one query at a time
    stop_shown = [[outcomes[0]], [outcomes[2]]]
    stop_judge = FixedJudge([0, 2, -1])
    for shown, table in zip(stop_shown, STOP.predictive_many(stop_shown, stop_judge, STOP.learner_model()), strict=True):
        assert np.array_equal(table, STOP.predictive(shown, stop_judge, STOP.learner_model()))


# ---------------------------------------------------------------------------------------------
# stop: a stub judge on a three-step kinematic trajectory
# z0 moves away at step 0, z1 at step 2, z2 never.

STOP_SCENE = Scene(objects=["red block", "blue block", "green block", "red bowl"])
THREE_STEPS = [PutIn(block="red block", bowl="red bowl"), PutOn(block="blue block", target="green block"),
               PutNextTo(block="blue block", target="red bowl", side="right")]
AWAY = np.array([0, 2, -1])
DT = 0.1


class FixedJudge:
    """A Judge whose hypotheses move away at fixed steps (utilities are not used by stop)."""

    def __init__(self, away):
        self.away = np.asarray(away)
        self.size = len(self.away)

    def first_away(self, traj):
        return self.away

    def utility(self, state):
        return np.zeros(self.size)


@pytest.fixture(scope="module")
def traj3():
    t = kinematic_trajectory(STOP_SCENE, 1, THREE_STEPS, dt=DT)
    assert [s.ok for s in t.steps] == [True, True, True]
    return t


def reveal(k: int) -> float:
    return (1 + STEP_TICKS * k + REVEAL) * DT


def lik(traj, t, model=None, away=AWAY) -> np.ndarray:
    answer = StopAnswer() if t is None else StopAnswer(stop_time=t)
    return STOP.likelihood(answer, [traj], FixedJudge(away), model or StopModel())


def test_no_stop_favours_the_hypothesis_with_nothing_wrong(traj3):
    p = lik(traj3, None)
    assert p[2] > 10 * p[0] and p[2] > 10 * p[1]
    assert p.min() > 0


def test_timely_stop_picks_the_step_that_moved_away(traj3):
    m = StopModel()
    assert np.argmax(lik(traj3, reveal(2) + m.delay_mean)) == 1
    assert np.argmax(lik(traj3, reveal(0) + m.delay_mean)) == 0


def test_early_stop_before_any_violation_is_a_false_stop_not_a_zero(traj3):
    p = lik(traj3, 0.2)  # before anything was revealed: no hypothesis predicts it
    assert p.min() > 0
    assert p.max() / p.min() < 5  # weak evidence only


def test_late_stop_still_points_at_the_offending_step_and_never_zeroes(traj3):
    p = lik(traj3, traj3.duration)  # 2 s after step 2 revealed: the end of τ
    assert p.min() > 0
    assert np.argmax(p) == 1  # only z1 had something go wrong that late
    assert lik(traj3, 100.0).min() > 0  # far beyond anything: the floor, never zero


def test_the_likelihood_peaks_where_the_model_says_a_person_presses(traj3):
    grid = np.linspace(0.0, traj3.duration, 1821)
    for visible_after in (0.0, 0.5):
        m = StopModel(delay_mean=0.6, delay_sd=0.2, visible_after=visible_after)
        density = np.array([lik(traj3, t, m)[0] for t in grid])
        end0 = traj3.time_of(traj3.steps[0].end_tick)
        expected = reveal(0) + visible_after * (end0 - reveal(0)) + m.delay_mean
        assert grid[np.argmax(density)] == pytest.approx(expected, abs=0.01)
    # log-normal delays: no press before the move is visible
    m = StopModel(delay="lognormal", delay_mean=0.7, delay_sd=0.35, late_tail=0.0)
    before, after = lik(traj3, reveal(0) - 0.05, m)[0], lik(traj3, reveal(0) + 0.6, m)[0]
    assert after > 50 * before


STOP_MODELS = [
    StopModel(),
    StopModel(delay="lognormal", delay_mean=0.7, delay_sd=0.35, visible_after=0.3, late_tail=0.1,
              false_stop=0.05, missed_stop=0.1, lapse=0.02),
    StopModel(delay_mean=0.4, delay_sd=0.1, late_tail=0.5, false_stop=0.2, missed_stop=0.3, lapse=0.1),
    STOP.learner_model(),
]


@pytest.mark.parametrize("model", STOP_MODELS, ids=["default", "human", "noisy", "learner"])
def test_stop_likelihood_is_a_normalised_density_plus_the_no_stop_mass(traj3, model):
    """∫ P(stop at t | z) dt over [0, span] + P(no stop | z) = 1 for every z (span: the end of τ
    plus the longest plausible delay, as in the model)."""
    span = traj3.duration + model.delay_mean + 3 * model.delay_sd
    grid = np.linspace(0.0, span, 8001)
    density = np.array([lik(traj3, t, model) for t in grid])  # [T, 3]
    mass = np.trapezoid(density, grid, axis=0) + lik(traj3, None, model)
    assert mass == pytest.approx([1.0, 1.0, 1.0], abs=0.03)


def test_discretised_stop_outcomes_sum_to_one(traj3):
    p = STOP.predictive([traj3], FixedJudge(AWAY), StopModel())
    assert p.shape == (3, 4)
    assert p.sum(axis=1) == pytest.approx(1.0)
    assert np.argmax(p[0]) == 0 and np.argmax(p[1]) == 2 and np.argmax(p[2]) == 3


def test_answer_at_locates_the_press_in_the_log_and_the_video(traj3):
    h = STOP.answer_at(traj3, 4.63)
    assert h.stopped and h.stop_time == pytest.approx(4.63)
    assert h.tick == traj3.tick_at(4.63) and h.frame == math.floor(4.63 * EXPORT_FPS)
    assert STOP.answer_at(traj3, 99.0).stop_time == pytest.approx(traj3.duration)
    assert STOP.answer_at(traj3, -1.0).stop_time == 0.0
    none = STOP.answer_at(traj3, None)
    assert not none.stopped and none.tick is None and none.frame is None


def test_a_stop_query_shows_exactly_one_trajectory(traj3):
    with pytest.raises(ValueError, match="one trajectory"):
        STOP.likelihood(StopAnswer(), [traj3, traj3], FixedJudge(AWAY), StopModel())


# ---------------------------------------------------------------------------------------------
# what one answer does to a belief (real hypotheses, the learner's own assumed models)

NAMES = ("all:in-same-bowl", "all:in-other-bowl", "all:one-bowl", "all:tower", "all:in-any-bowl")
_BY_NAME = {h.name: h for h in hypothesis_space()}
HYPS = tuple(_BY_NAME[n] for n in NAMES)  # kept alive: judges memoise per hypothesis tuple
START = WorldState(positions=layout(SCENE, 2))


def posterior_after(signal, answers, shown) -> tuple[np.ndarray, np.ndarray]:
    belief = Belief(HYPS, prior="uniform")
    prior = belief.weights.copy()
    judge = HypothesisJudge(HYPS)
    for h in answers:
        belief.update(signal.likelihood(h, shown, judge, signal.learner_model()))
    return prior, belief.weights


def idx(name: str) -> int:
    return NAMES.index(name)


@pytest.fixture(scope="module")
def ab():
    """A: each block in its own colour's bowl; B: each block in the other bowl."""
    return [symbolic_trajectory(SCENE, START, MATCH), symbolic_trajectory(SCENE, START, SWAP)]


@pytest.mark.parametrize("choice, up, down", [("A", "all:in-same-bowl", "all:in-other-bowl"),
                                              ("B", "all:in-other-bowl", "all:in-same-bowl")])
def test_a_preference_moves_belief_towards_the_hypothesis_that_predicts_it(ab, choice, up, down):
    prior, post = posterior_after(PREF, [PreferenceAnswer(choice=choice)], ab)
    assert post[idx(up)] > prior[idx(up)]
    assert post[idx(down)] < prior[idx(down)]
    assert post[idx(up)] > 5 * post[idx(down)]


def test_cant_choose_favours_the_hypotheses_indifferent_to_the_pair(ab):
    # both outcomes put every block in a bowl: "any bowl" cannot tell them apart
    prior, post = posterior_after(PREF, [PreferenceAnswer(choice="cant_choose")], ab)
    assert post[idx("all:in-any-bowl")] > prior[idx("all:in-any-bowl")]
    assert post[idx("all:in-same-bowl")] < prior[idx("all:in-same-bowl")]
    assert post[idx("all:in-other-bowl")] < prior[idx("all:in-other-bowl")]


def test_one_wrong_preference_does_not_zero_the_true_hypothesis(ab):
    model = PREF.learner_model()
    prior, post = posterior_after(PREF, [PreferenceAnswer(choice="B")], ab)  # truth: in-same-bowl
    true = idx("all:in-same-bowl")
    # Bayes' rule with the lapse floor P(h | z) ≥ λ/3 and P(h) ≤ 1
    assert post[true] >= prior[true] * model.lapse / 3 * (1 - 1e-9)
    # and it recovers: three right answers after the wrong one make it the most probable again
    _, post = posterior_after(PREF, [PreferenceAnswer(choice="B")] + [PreferenceAnswer(choice="A")] * 3, ab)
    assert int(np.argmax(post)) == true


@pytest.fixture(scope="module")
def red_then_blue_in_blue():
    """Step 0 puts the red block in the blue bowl, step 1 the blue block: "same bowl" and
    "tower" object at step 0, "other bowl" at step 1, "one bowl" and "any bowl" never."""
    plan = [PutIn(block="red block", bowl="blue bowl"), PutIn(block="blue block", bowl="blue bowl")]
    traj = symbolic_trajectory(SCENE, START, plan)
    away = HypothesisJudge(HYPS).first_away(traj)
    assert dict(zip(NAMES, away.tolist(), strict=True)) == {
        "all:in-same-bowl": 0, "all:in-other-bowl": 1, "all:one-bowl": -1, "all:tower": 0, "all:in-any-bowl": -1}
    return traj


def press(traj, step: int) -> StopAnswer:
    """A press one typical reaction delay after step ``step`` became visible."""
    m = STOP.learner_model()
    return STOP.answer_at(traj, traj.time_of(traj.steps[step].reveal_tick) + m.delay_mean)


def test_no_stop_moves_belief_to_the_hypotheses_nothing_moved_away_from(red_then_blue_in_blue):
    prior, post = posterior_after(STOP, [StopAnswer()], [red_then_blue_in_blue])
    for name in ("all:one-bowl", "all:in-any-bowl"):
        assert post[idx(name)] > prior[idx(name)]
    for name in ("all:in-same-bowl", "all:in-other-bowl", "all:tower"):
        assert post[idx(name)] < prior[idx(name)]


@pytest.mark.parametrize("step, up", [(0, ("all:in-same-bowl", "all:tower")), (1, ("all:in-other-bowl",))])
def test_a_timely_stop_moves_belief_to_the_hypotheses_that_object_to_that_step(red_then_blue_in_blue, step, up):
    traj = red_then_blue_in_blue
    prior, post = posterior_after(STOP, [press(traj, step)], [traj])
    for i, name in enumerate(NAMES):
        if name in up:
            assert post[i] > prior[i], name
        else:
            assert post[i] < prior[i], name


def test_one_wrong_stop_does_not_zero_the_true_hypothesis(red_then_blue_in_blue):
    traj = red_then_blue_in_blue
    true = idx("all:one-bowl")  # nothing in τ moves away from it; the person stops anyway
    m = STOP.learner_model()
    prior, post = posterior_after(STOP, [press(traj, 0)], [traj])
    span = traj.duration + m.delay_mean + 3 * m.delay_sd
    floor = (1 - m.lapse) * m.false_stop / span + m.lapse / (2 * span)  # P(stop at t | z) with nothing wrong
    lik_all = STOP.likelihood(press(traj, 0), [traj], HypothesisJudge(HYPS), m)
    assert lik_all[true] == pytest.approx(floor)
    assert post[true] >= prior[true] * floor / lik_all.max() * (1 - 1e-9) > 0
    # two answers that agree with it bring it back on top
    _, post = posterior_after(STOP, [press(traj, 0), StopAnswer(), StopAnswer()], [traj])
    assert post[true] == pytest.approx(post.max())
