"""The simulated stop user: where it stops, reaction-delay statistics, false and missed stops,
bounds, determinism, and the config/factory."""

import json
import math

import numpy as np
import pytest

from activeintent.intentions import get_intention
from activeintent.sim.trajectory import StepRecord
from activeintent.users.simulated import StopUser, UserConfig, make_user
from activeintent.world import PutIn, PutNextTo, PutOn, Scene
from helpers import REVEAL, STEP_TICKS, kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "green block", "red bowl"])
SEED = 1
DT = 0.1

GOOD_STACK = [PutOn(block="blue block", target="red block"), PutOn(block="green block", target="blue block")]
BAD_SECOND = [PutOn(block="blue block", target="red block"), PutIn(block="green block", bowl="red bowl")]
BAD_BOTH = [PutIn(block="blue block", bowl="red bowl"), PutNextTo(block="green block", target="red block")]


def reveal_time(step_index: int) -> float:
    return (1 + STEP_TICKS * step_index + REVEAL) * DT


def exact_user(name="stack", **kw) -> StopUser:
    return StopUser(get_intention(name), reaction_delay=(0.5, 0.0), rng=np.random.default_rng(0), **kw)


def test_no_stop_when_nothing_goes_wrong():
    traj = kinematic_trajectory(SCENE, SEED, GOOD_STACK)
    h = exact_user().respond(SCENE, [traj])
    assert h.stop_time is None and not h.stopped and h.tick is None and h.step_index is None


def test_stops_at_the_first_bad_step_after_the_reaction_delay():
    traj = kinematic_trajectory(SCENE, SEED, BAD_SECOND)
    h = exact_user().respond(SCENE, [traj])
    assert h.stop_time == pytest.approx(reveal_time(1) + 0.5)
    assert h.step_index == 1
    assert h.tick == traj.tick_at(h.stop_time)
    assert h.frame == math.floor(h.stop_time * 10 + 1e-9) == 46
    h = exact_user().respond(SCENE, [kinematic_trajectory(SCENE, SEED, BAD_BOTH)])
    assert h.step_index == 0 and h.stop_time == pytest.approx(reveal_time(0) + 0.5)


def test_the_stop_depends_on_the_intention():
    traj = kinematic_trajectory(SCENE, SEED, BAD_SECOND)
    # Putting the green block in a bowl is fine for "one bowl"... but stacking first is not.
    h = exact_user("one-bowl").respond(SCENE, [traj])
    assert h.step_index == 0
    align = kinematic_trajectory(SCENE, SEED, [PutNextTo(block="blue block", target="red block", side="right")])
    assert exact_user("align").respond(SCENE, [align]).stop_time is None
    assert exact_user("stack").respond(SCENE, [align]).step_index == 0


def test_failed_step_is_not_a_move_away():
    # Putting a block on itself fails and changes nothing.
    traj = kinematic_trajectory(SCENE, SEED, [PutOn(block="blue block", target="blue block"), *GOOD_STACK])
    assert not traj.steps[0].ok
    assert exact_user().respond(SCENE, [traj]).stop_time is None


def test_failed_step_that_breaks_progress_is_a_move_away():
    traj = kinematic_trajectory(SCENE, SEED, GOOD_STACK)
    good = traj.steps[1]
    # A failed attempt that knocked the tower over: the state after is the initial one.
    knocked = StepRecord(index=1, skill=good.skill, start_tick=good.start_tick, reveal_tick=good.reveal_tick,
                         end_tick=good.end_tick, ok=False, reason="fell", state_before=good.state_before,
                         state_after=traj.steps[0].state_before)
    traj.steps[1] = knocked
    assert exact_user().respond(SCENE, [traj]).step_index == 1


def test_stop_is_clipped_to_the_end_and_never_negative():
    traj = kinematic_trajectory(SCENE, SEED, BAD_SECOND)
    late = StopUser(get_intention("stack"), reaction_delay=(100.0, 0.0), rng=np.random.default_rng(0))
    h = late.respond(SCENE, [traj])
    assert h.stop_time == pytest.approx(traj.duration)
    assert h.tick == traj.n_ticks - 1
    # Delays are truncated at 0: with a mean of 0 half the normal draws would be negative.
    early = StopUser(get_intention("stack"), reaction_delay=(0.0, 0.3), rng=np.random.default_rng(1))
    times = [early.respond(SCENE, [traj]).stop_time for _ in range(500)]
    assert min(times) >= reveal_time(1) - 1e-12


N = 4000


def test_reaction_delay_statistics():
    traj = kinematic_trajectory(SCENE, SEED, BAD_SECOND)
    user = make_user("stop", get_intention("stack"), UserConfig(), seed=2)  # mean 0.5 s, sd 0.15 s
    delays = np.array([user.respond(SCENE, [traj]).stop_time - reveal_time(1) for _ in range(N)])
    assert delays.min() >= 0
    # Truncation at 0 is 3.3 sd away: the moments are those of the normal.
    assert abs(delays.mean() - 0.5) <= 3 * 0.15 / math.sqrt(N)
    assert abs(delays.std() - 0.15) <= 3 * 0.15 / math.sqrt(2 * (N - 1))


def within(count: int, p: float, n: int = N) -> bool:
    return abs(count / n - p) <= 3 * math.sqrt(p * (1 - p) / n) + 1e-3


def test_false_stop_rate_and_times():
    traj = kinematic_trajectory(SCENE, SEED, GOOD_STACK)
    user = make_user("stop", get_intention("stack"), UserConfig(false_stop=0.2), seed=3)
    answers = [user.respond(SCENE, [traj]) for _ in range(N)]
    times = [h.stop_time for h in answers if h.stopped]
    assert within(len(times), 0.2)
    assert 0 <= min(times) and max(times) <= traj.duration
    # Spread over the whole trajectory (uniform): mean near the middle.
    assert abs(np.mean(times) - traj.duration / 2) < 0.1 * traj.duration


def test_missed_stop_rate():
    user = make_user("stop", get_intention("stack"), UserConfig(missed_stop=0.3), seed=4)
    one_bad = kinematic_trajectory(SCENE, SEED, BAD_SECOND)
    assert within(sum(not user.respond(SCENE, [one_bad]).stopped for _ in range(N)), 0.3)
    # Two bad steps: each is missed independently; the user reacts to the second with p = 0.3·0.7.
    two_bad = kinematic_trajectory(SCENE, SEED, BAD_BOTH)
    answers = [user.respond(SCENE, [two_bad]) for _ in range(N)]
    assert within(sum(h.step_index == 0 for h in answers), 0.7)
    assert within(sum(h.step_index == 1 for h in answers), 0.21)
    assert within(sum(not h.stopped for h in answers), 0.09)


def test_deterministic_from_the_seed():
    traj = kinematic_trajectory(SCENE, SEED, BAD_SECOND)
    config = UserConfig(false_stop=0.3, missed_stop=0.2)

    def run(seed):
        user = make_user("stop", get_intention("stack"), config, seed=seed)
        return [user.respond(SCENE, [traj]).stop_time for _ in range(30)]

    assert run(9) == run(9)
    assert run(9) != run(10)


def test_new_scene_when_the_intention_cannot_be_shown():
    scene = Scene(objects=["red block", "red bowl", "blue bowl"])  # stack needs two blocks
    traj = kinematic_trajectory(scene, 0, [])
    h = exact_user().respond(scene, [traj])
    assert h.new_scene and h.stop_time is None


def test_respond_needs_one_trajectory():
    traj = kinematic_trajectory(SCENE, SEED, [])
    with pytest.raises(ValueError, match="exactly one"):
        exact_user().respond(SCENE, [traj, traj])


def test_make_user_and_config_logging():
    stack = get_intention("stack")
    assert make_user("stop", stack).signal == "stop"
    assert make_user("preference", stack).signal == "preference"
    with pytest.raises(ValueError, match="valid signals: preference, stop"):
        make_user("clicker", stack)
    config = UserConfig(beta=float("inf"), false_stop=0.1)
    logged = json.loads(config.model_dump_json())
    assert logged["beta"] == math.inf and logged["reaction_delay_mean"] == 0.5
    assert UserConfig.model_validate(logged) == config
    with pytest.raises(ValueError):
        UserConfig(false_stop=1.5)
    with pytest.raises(ValueError):
        UserConfig(unknown=1)
