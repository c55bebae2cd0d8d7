"""The simulated preference user: exact answers on crafted pairs, noisy answers whose
frequencies match the choice model of the preference signal, and determinism from the seed.

The choice model's own numbers (utility, similarity, closed forms) are tested with the
signal, in tests/signals/test_signal_models.py.
"""

import math

import pytest

from activeintent.intentions import get_intention
from activeintent.signals.preference import CHOICES
from activeintent.users.simulated import SimulatedUser, UserProfile, user_profile
from activeintent.world import PutIn, PutNextTo, PutOn, Scene
from helpers import kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "red bowl", "blue bowl"])
SEED = 3

MATCH = [PutIn(block="red block", bowl="red bowl"), PutIn(block="blue block", bowl="blue bowl")]
HALF = [PutIn(block="red block", bowl="red bowl")]
SWAP = [PutIn(block="red block", bowl="blue bowl"), PutIn(block="blue block", bowl="red bowl")]
STACK = [PutOn(block="red block", target="blue block")]
ROW = [PutNextTo(block="red block", target="blue block", side="right")]


def shown(a, b, scene=SCENE, seed=SEED):
    ta, tb = kinematic_trajectory(scene, seed, a), kinematic_trajectory(scene, seed, b)
    assert all(s.ok for s in ta.steps + tb.steps)
    return [ta, tb]


def exact(name: str, seed: int = 0) -> SimulatedUser:
    return SimulatedUser(get_intention(name), "preference", user_profile("exact"), rng=seed)


def noisy(name: str, seed: int, **model) -> SimulatedUser:
    return SimulatedUser(get_intention(name), "preference", UserProfile(models={"preference": model}), rng=seed)


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
    trajs = shown(a, b)
    for _ in range(5):  # no noise: always the same answer
        h = user.respond(SCENE, trajs)
        assert not h.new_scene and h.choice == expected
    # the signal's model gives that answer probability one
    p = user.signal.predictive(trajs, user.judge, user.model)[0]
    assert p[CHOICES.index(expected)] == 1.0


def test_exact_user_asks_for_a_new_scene_when_infeasible():
    scene = Scene(objects=["red block", "green block", "blue bowl"])  # no bowl of a block's colour
    assert not get_intention("color-match").feasible(scene)
    ta = kinematic_trajectory(scene, 0, [])
    for seed in range(5):
        h = exact("color-match", seed).respond(scene, [ta, ta])
        assert h.new_scene and h.choice is None
    # a user who never notices (new_scene_miss = 1) answers the query instead
    blind = user_profile("exact").model_copy(update={"new_scene_miss": 1.0})
    user = SimulatedUser(get_intention("color-match"), "preference", blind, rng=0)
    assert user.respond(scene, [ta, ta]).choice == "cant_choose"


def test_respond_needs_two_trajectories():
    ta = kinematic_trajectory(SCENE, SEED, [])
    with pytest.raises(ValueError, match="two trajectories"):
        exact("stack").respond(SCENE, [ta])


N_DRAWS = 4000


@pytest.mark.parametrize(
    "intention, a, b, model",
    [
        ("color-match", MATCH, SWAP, {"beta": 4.0, "confusion": 1.0, "lapse": 0.0}),  # clear difference
        ("color-match", HALF, SWAP, {"beta": 6.0, "confusion": 1.0, "lapse": 0.0}),  # small difference
        ("color-match", MATCH, HALF, {"beta": 3.0, "confusion": 2.0, "lapse": 0.0}),  # similar outcomes
        ("stack", ROW, SWAP, {"beta": 2.0, "confusion": 1.0, "lapse": 0.0}),  # equally bad
        ("color-match", MATCH, SWAP, {"beta": 30.0, "lapse": 0.3}),  # lapses dominate the noise
    ],
)
def test_noisy_user_frequencies_match_the_model(intention, a, b, model):
    user = noisy(intention, 11, **model)
    trajs = shown(a, b)
    expected = user.signal.predictive(trajs, user.judge, user.model)[0]
    assert expected.min() > 0.01  # the case really is noisy
    counts = dict.fromkeys(CHOICES, 0)
    for _ in range(N_DRAWS):
        counts[user.respond(SCENE, trajs).choice] += 1
    for choice, p in zip(CHOICES, expected, strict=True):
        # 4 standard errors of a binomial share: 15 comparisons, each off by chance < 1e-4
        sigma = math.sqrt(p * (1 - p) / N_DRAWS)
        assert abs(counts[choice] / N_DRAWS - p) <= 4 * sigma, (choice, counts, expected)


def test_noisy_user_is_deterministic_from_its_seed():
    trajs = shown(HALF, SWAP)

    def answers(seed):
        user = noisy("color-match", seed, beta=2.0)
        return [user.respond(SCENE, trajs).choice for _ in range(50)]

    assert answers(5) == answers(5)
    assert answers(5) != answers(6)


def test_the_user_answers_with_its_own_parameters_not_the_learners():
    user = noisy("color-match", 0, beta=2.0, indifference=0.2, lapse=0.1)
    assert (user.model.beta, user.model.indifference, user.model.lapse) == (2.0, 0.2, 0.1)
    assert user.parameters()["signal_model"]["beta"] == 2.0
    assert user.model != user.signal.learner_model()
