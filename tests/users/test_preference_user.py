"""The simulated preference user: exact answers on crafted pairs, and noisy answers whose
frequencies match the choice model."""

import math

import numpy as np
import pytest

from activeintent.intentions import get_intention
from activeintent.users.preference_model import (
    outcome_similarity,
    outcome_utility,
    preference_probabilities,
)
from activeintent.users.simulated import PreferenceUser, UserConfig, make_user
from activeintent.world import PutIn, PutNextTo, PutOn, Scene, WorldState, apply_plan, layout
from helpers import kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "red bowl", "blue bowl"])
SEED = 3


def outcome(plan) -> WorldState:
    state = WorldState(positions=layout(SCENE, SEED))
    states, failures = apply_plan(state, plan)
    assert failures == [None] * len(plan)
    return states[-1] if states else state


MATCH = [PutIn(block="red block", bowl="red bowl"), PutIn(block="blue block", bowl="blue bowl")]
HALF = [PutIn(block="red block", bowl="red bowl")]
SWAP = [PutIn(block="red block", bowl="blue bowl"), PutIn(block="blue block", bowl="red bowl")]
STACK = [PutOn(block="red block", target="blue block")]
ROW = [PutNextTo(block="red block", target="blue block", side="right")]


def exact(name: str) -> PreferenceUser:
    return PreferenceUser(get_intention(name), rng=np.random.default_rng(0))


@pytest.mark.parametrize(
    "intention, a, b, expected",
    [
        ("color-match", MATCH, SWAP, "A"),
        ("color-match", SWAP, MATCH, "B"),
        ("color-match", HALF, SWAP, "A"),  # half right beats all wrong
        ("color-match", MATCH, MATCH, "cant_choose"),  # equally good
        ("color-match", SWAP, STACK, "cant_choose"),  # equally bad
        ("color-mismatch", MATCH, SWAP, "B"),
        ("stack", STACK, ROW, "A"),
        ("align", STACK, ROW, "B"),
        ("align", [], [], "cant_choose"),
    ],
)
def test_exact_user_answers_as_the_intention_says(intention, a, b, expected):
    user = exact(intention)
    assert user.choose(outcome(a), outcome(b)).choice == expected
    # The same through respond() on trajectories.
    ta, tb = kinematic_trajectory(SCENE, SEED, a), kinematic_trajectory(SCENE, SEED, b)
    assert user.respond(SCENE, [ta, tb]).choice == expected


def test_exact_user_asks_for_a_new_scene_when_infeasible():
    scene = Scene(objects=["red block", "green block", "blue bowl"])  # no matching bowls
    ta = kinematic_trajectory(scene, 0, [])
    assert exact("color-match").respond(scene, [ta, ta]).choice == "new_scene"
    user = PreferenceUser(get_intention("color-match"), new_scene_when_infeasible=False)
    assert user.respond(scene, [ta, ta]).choice == "cant_choose"


def test_respond_needs_two_trajectories():
    ta = kinematic_trajectory(SCENE, SEED, [])
    with pytest.raises(ValueError, match="exactly two"):
        exact("stack").respond(SCENE, [ta])


def test_utility_and_similarity():
    match = get_intention("color-match")
    assert outcome_utility(match, outcome(MATCH)) == 1.0
    assert outcome_utility(match, outcome(HALF)) == pytest.approx(0.25)
    assert outcome_utility(match, outcome(SWAP)) == 0.0
    assert outcome_similarity(outcome(MATCH), outcome(MATCH)) == pytest.approx(1.0)
    assert outcome_similarity(outcome(MATCH), outcome(HALF)) < 1.0
    assert outcome_similarity(outcome(MATCH), outcome(SWAP)) < 0.01


def test_model_probabilities_properties():
    for args in [(0.9, 0.1, 0.0, 3.0), (0.5, 0.5, 0.8, 2.0), (0.2, 0.7, 0.3, 0.0)]:
        p = preference_probabilities(*args)
        assert sum(p.values()) == pytest.approx(1.0)
    # β = 0 without similarity: uniform; similarity raises cant_choose, whatever β.
    assert preference_probabilities(1, 0, 0.0, beta=0.0, confusion=1.0)["A"] == pytest.approx(1 / 3)
    low = preference_probabilities(0.6, 0.4, 0.0, beta=5.0)["cant_choose"]
    high = preference_probabilities(0.6, 0.4, 0.9, beta=5.0)["cant_choose"]
    assert high > low
    # Large β approaches the exact user; an exact tie is cant_choose.
    assert preference_probabilities(0.6, 0.4, 0.5, beta=500.0)["A"] > 0.99
    assert preference_probabilities(0.6, 0.4, 0.5, beta=math.inf) == {"A": 1.0, "B": 0.0, "cant_choose": 0.0}
    assert preference_probabilities(0.4, 0.4, 0.0, beta=math.inf, indifference=0.0)["cant_choose"] == 1.0
    # Closed form: P(C)/P(A) = exp(β(m − |d|/2) + κσ − βd/2).
    p = preference_probabilities(0.7, 0.3, 0.5, beta=4.0, indifference=0.05, confusion=2.0)
    assert p["cant_choose"] / p["A"] == pytest.approx(math.exp(4.0 * (0.05 - 0.2) + 1.0 - 4.0 * 0.2))
    assert p["B"] / p["A"] == pytest.approx(math.exp(-4.0 * 0.4))


N_DRAWS = 4000


@pytest.mark.parametrize(
    "intention, a, b, beta, confusion",
    [
        ("color-match", MATCH, SWAP, 4.0, 1.0),  # clear difference
        ("color-match", HALF, SWAP, 6.0, 1.0),  # small difference
        ("color-match", MATCH, HALF, 3.0, 2.0),  # similar outcomes
        ("stack", ROW, SWAP, 2.0, 1.0),  # equally bad
    ],
)
def test_noisy_user_frequencies_match_the_model(intention, a, b, beta, confusion):
    config = UserConfig(beta=beta, confusion=confusion)
    user = make_user("preference", get_intention(intention), config, seed=11)
    sa, sb = outcome(a), outcome(b)
    expected = user.probabilities(sa, sb)
    counts = {"A": 0, "B": 0, "cant_choose": 0}
    for _ in range(N_DRAWS):
        counts[user.choose(sa, sb).choice] += 1
    for choice, p in expected.items():
        sigma = math.sqrt(p * (1 - p) / N_DRAWS)
        assert abs(counts[choice] / N_DRAWS - p) <= 3 * sigma + 1e-3, (choice, counts, expected)
    assert min(expected.values()) > 0.0  # the case really is noisy


def test_noisy_user_is_deterministic_from_its_seed():
    config = UserConfig(beta=2.0)
    sa, sb = outcome(HALF), outcome(SWAP)

    def answers(seed):
        user = make_user("preference", get_intention("color-match"), config, seed=seed)
        return [user.choose(sa, sb).choice for _ in range(50)]

    assert answers(5) == answers(5)
    assert answers(5) != answers(6)
