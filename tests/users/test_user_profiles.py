"""User profiles and presets, for every signal: the β drawn per `human` user, the new-scene
error rates of a profile, the exact user's new-scene answers, and what a user logs."""

import json
import math

import numpy as np
import pytest
from pydantic import ValidationError

from activeintent.intentions import get_intention
from activeintent.intentions.registry import INTENTION_NAMES
from activeintent.signals import get_signal
from activeintent.users.simulated import USER_PRESETS, SimulatedUser, UserProfile, user_profile
from activeintent.world import PutIn, Scene, WorldState, layout, sample_scene
from helpers import kinematic_trajectory

FEASIBLE = Scene(objects=["red block", "blue block", "red bowl", "blue bowl"])  # color-match can be shown
INFEASIBLE = Scene(objects=["red block", "green block", "blue bowl"])  # no bowl of a block's colour
N = 2000


def within(count: int, p: float, n: int = N) -> bool:
    """A binomial share within 4 standard errors (plus 1/n for p near 0 or 1)."""
    return abs(count / n - p) <= 4 * math.sqrt(p * (1 - p) / n) + 1 / n


def shown(signal: str, scene: Scene, plan=()) -> list:
    t = kinematic_trajectory(scene, 0, list(plan))
    return [t] * get_signal(signal).shows


def test_presets_are_registered_and_unknown_ones_refused():
    assert {"exact", "paper", "human"} <= set(USER_PRESETS.names())
    with pytest.raises(ValueError, match=r"valid user presets: .*exact.*paper.*human"):
        user_profile("robot")


def test_human_preset_draws_beta_per_user_within_2_to_5():
    betas = []
    for seed in range(200):
        u = SimulatedUser(get_intention("color-match"), "preference", user_profile("human"), rng=seed)
        assert 2.0 <= u.model.beta <= 5.0
        assert u.parameters()["signal_model"]["beta"] == u.model.beta  # logged as drawn
        assert (u.model.indifference, u.model.lapse) == (0.1, 0.05)  # the rest from the preset
        betas.append(u.model.beta)
    assert len(set(betas)) == len(betas)  # one draw per user
    assert min(betas) < 2.3 and max(betas) > 4.7  # spread over the range (uniform)
    again = SimulatedUser(get_intention("color-match"), "preference", user_profile("human"), rng=7)
    assert again.model.beta == betas[7]  # the draw comes from the user's seed


def test_presets_that_fix_beta_do_not_draw_it():
    for preset, beta in (("exact", math.inf), ("paper", 20.0)):
        u = SimulatedUser(get_intention("stack"), "preference", user_profile(preset), rng=3)
        assert u.model.beta == beta
    # a stop user has no β: the human preset's stop model is its own
    stop = SimulatedUser(get_intention("stack"), "stop", user_profile("human"), rng=3)
    assert stop.model.delay == "lognormal" and "beta" not in stop.parameters()["signal_model"]


@pytest.mark.parametrize("signal", ["stop", "preference"])
@pytest.mark.parametrize("profile", [
    user_profile("paper"),
    user_profile("human"),
    UserProfile(new_scene_false=0.3, new_scene_miss=0.4),
], ids=["paper", "human", "custom"])
def test_new_scene_error_rates_of_a_profile_are_respected(signal, profile):
    intention = get_intention("color-match")
    assert intention.feasible(FEASIBLE) and not intention.feasible(INFEASIBLE)
    u = SimulatedUser(intention, signal, profile, rng=12)
    good, bad = shown(signal, FEASIBLE), shown(signal, INFEASIBLE)
    asked = sum(u.respond(FEASIBLE, good).new_scene for _ in range(N))
    assert within(asked, profile.new_scene_false), (asked, profile.new_scene_false)
    answered = sum(not u.respond(INFEASIBLE, bad).new_scene for _ in range(N))
    assert within(answered, profile.new_scene_miss), (answered, profile.new_scene_miss)


@pytest.mark.parametrize("signal", ["stop", "preference"])
def test_exact_user_never_asks_for_a_new_scene_in_a_feasible_scene(signal):
    rng = np.random.default_rng(0)
    checked = 0
    for name in INTENTION_NAMES:
        intention = get_intention(name)
        u = SimulatedUser(intention, signal, user_profile("exact"), rng=checked)
        for _ in range(4):
            scene = intention.sample_scene(rng)
            assert intention.feasible(scene), (name, scene)
            state = WorldState(positions=layout(scene, 0))
            plan = intention.plan(state) or []
            trajs = [kinematic_trajectory(scene, 0, plan)] * u.signal.shows
            assert not u.respond(scene, trajs).new_scene, (name, scene)
            checked += 1
    assert checked == 4 * len(INTENTION_NAMES)


@pytest.mark.parametrize("signal", ["stop", "preference"])
def test_exact_user_always_asks_for_a_new_scene_in_an_infeasible_one(signal):
    rng = np.random.default_rng(1)
    found = 0
    for name in INTENTION_NAMES:
        intention = get_intention(name)
        u = SimulatedUser(intention, signal, user_profile("exact"), rng=0)
        for _ in range(20):
            scene = sample_scene(rng, n_blocks=(1, 3), n_bowls=2)
            if not intention.feasible(scene):
                assert u.respond(scene, shown(signal, scene)).new_scene, (name, scene)
                found += 1
    assert found > 20  # the check did run


def test_user_accepts_a_signal_by_name_or_object_and_refuses_unknown_ones():
    stack = get_intention("stack")
    assert SimulatedUser(stack, "stop").signal.name == "stop"
    assert SimulatedUser(stack, get_signal("preference")).signal.name == "preference"
    assert SimulatedUser(stack, "stop").profile.name == "exact"  # the default profile
    with pytest.raises(ValueError, match=r"valid signals: .*preference.*stop"):
        SimulatedUser(stack, "clicker")


def test_all_randomness_comes_from_the_users_own_generator():
    t = kinematic_trajectory(FEASIBLE, 0, [PutIn(block="red block", bowl="blue bowl")])

    def answers():
        u = SimulatedUser(get_intention("color-match"), "stop", user_profile("human"), rng=5)
        return [u.respond(FEASIBLE, [t]).model_dump() for _ in range(40)]

    np.random.seed(1)
    first = answers()
    np.random.seed(2)
    assert answers() == first


def test_profiles_are_validated():
    with pytest.raises(ValidationError):
        UserProfile(unknown=1)
    with pytest.raises(ValidationError):
        UserProfile(new_scene_false=1.5)
    bad_model = UserProfile(models={"stop": {"false_stop": 1.5}})
    with pytest.raises(ValidationError):
        SimulatedUser(get_intention("stack"), "stop", bad_model)
    typo = UserProfile(models={"stop": {"reaction_delay": 0.5}})
    with pytest.raises(ValidationError):
        SimulatedUser(get_intention("stack"), "stop", typo)


def test_parameters_are_json_and_keep_an_infinite_beta():
    u = SimulatedUser(get_intention("stack"), "preference", user_profile("exact"))
    logged = json.loads(json.dumps(u.parameters()))
    assert logged["signal_model"]["beta"] == math.inf
    assert logged["profile"]["name"] == "exact"


@pytest.mark.parametrize("preset", ["paper", "human", "exact"])
def test_a_profile_survives_a_json_round_trip(preset):
    profile = user_profile(preset)
    again = UserProfile.model_validate_json(profile.model_dump_json())
    assert again == profile
    u = SimulatedUser(get_intention("stack"), "preference", again, rng=0)
    assert u.model == SimulatedUser(get_intention("stack"), "preference", profile, rng=0).model
