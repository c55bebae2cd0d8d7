"""The simulated stop user: where it stops, reaction-delay statistics, false, missed, late and
lapsed stops against the stop model's probabilities, bounds, determinism, and its profile."""

import math

import numpy as np
import pytest

from activeintent.intentions import get_intention
from activeintent.users.simulated import SimulatedUser, UserProfile, user_profile
from activeintent.world import PutIn, PutNextTo, PutOn, Scene
from activeintent.world.trajectory import StepRecord
from helpers import REVEAL, STEP_TICKS, kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "green block", "red bowl"])
SEED = 1
DT = 0.1

GOOD_STACK = [PutOn(block="blue block", target="red block"), PutOn(block="green block", target="blue block")]
BAD_SECOND = [PutOn(block="blue block", target="red block"), PutIn(block="green block", bowl="red bowl")]
BAD_BOTH = [PutIn(block="blue block", bowl="red bowl"), PutNextTo(block="green block", target="red block")]

# no noise at all, and a fixed reaction delay of 0.5 s
CLEAN = {"delay_mean": 0.5, "delay_sd": 0.0, "late_tail": 0.0, "false_stop": 0.0, "missed_stop": 0.0, "lapse": 0.0}


def reveal_time(step_index: int) -> float:
    return (1 + STEP_TICKS * step_index + REVEAL) * DT


def user(name="stack", seed=0, **stop) -> SimulatedUser:
    return SimulatedUser(get_intention(name), "stop", UserProfile(models={"stop": {**CLEAN, **stop}}), rng=seed)


def traj(plan, scene=SCENE):
    return kinematic_trajectory(scene, SEED, plan, dt=DT)


def test_no_stop_when_nothing_goes_wrong():
    h = user().respond(SCENE, [traj(GOOD_STACK)])
    assert not h.new_scene and h.stop_time is None and not h.stopped and h.tick is None and h.frame is None


def test_stops_at_the_first_bad_step_after_the_reaction_delay():
    t = traj(BAD_SECOND)
    h = user().respond(SCENE, [t])
    assert h.stop_time == pytest.approx(reveal_time(1) + 0.5)
    assert t.step_at(h.stop_time) == 1
    assert h.tick == t.tick_at(h.stop_time)
    assert h.frame == math.floor(h.stop_time * 10 + 1e-9) == 46
    t = traj(BAD_BOTH)
    h = user().respond(SCENE, [t])
    assert h.stop_time == pytest.approx(reveal_time(0) + 0.5) and t.step_at(h.stop_time) == 0


def test_the_press_waits_until_the_move_is_visible():
    t = traj(BAD_SECOND)
    step = t.steps[1]
    h = user(visible_after=0.5).respond(SCENE, [t])
    seen = reveal_time(1) + 0.5 * (t.time_of(step.end_tick) - t.time_of(step.reveal_tick))
    assert h.stop_time == pytest.approx(seen + 0.5)


def test_the_stop_depends_on_the_intention():
    t = traj(BAD_SECOND)
    # Putting the green block in a bowl is fine for "one bowl"... but stacking first is not.
    h = user("one-bowl").respond(SCENE, [t])
    assert t.step_at(h.stop_time) == 0
    align = traj([PutNextTo(block="blue block", target="red block", side="right")])
    assert user("align").respond(SCENE, [align]).stop_time is None
    h = user("stack").respond(SCENE, [align])
    assert h.stopped and align.step_at(h.stop_time) == 0


def test_failed_step_is_not_a_move_away():
    # Putting a block on itself fails and changes nothing.
    t = traj([PutOn(block="blue block", target="blue block"), *GOOD_STACK])
    assert not t.steps[0].ok
    assert user().respond(SCENE, [t]).stop_time is None


def test_failed_step_that_breaks_progress_is_a_move_away():
    t = traj(GOOD_STACK)
    good = t.steps[1]
    # A failed attempt that knocked the tower over: the state after is the initial one.
    t.steps[1] = StepRecord(index=1, skill=good.skill, start_tick=good.start_tick, reveal_tick=good.reveal_tick,
                            end_tick=good.end_tick, ok=False, reason="fell", state_before=good.state_before,
                            state_after=t.steps[0].state_before)
    h = user().respond(SCENE, [t])
    assert h.stop_time == pytest.approx(reveal_time(1) + 0.5)


def test_stop_is_clipped_to_the_end_and_never_negative():
    t = traj(BAD_SECOND)
    h = user(delay_mean=100.0).respond(SCENE, [t])
    assert h.stop_time == pytest.approx(t.duration)
    assert h.tick == t.n_ticks - 1
    # Normal delays are folded at 0: with a mean of 0 half the draws would be negative.
    early = user(delay_mean=0.0, delay_sd=0.3, seed=1)
    times = [early.respond(SCENE, [t]).stop_time for _ in range(500)]
    assert min(times) >= reveal_time(1) - 1e-12


N = 4000


def within(count: int, p: float, n: int = N) -> bool:
    """A binomial share within 4 standard errors (plus 1/n for p near 0 or 1)."""
    return abs(count / n - p) <= 4 * math.sqrt(p * (1 - p) / n) + 1 / n


def test_normal_reaction_delay_statistics():
    t = traj(BAD_SECOND)
    u = SimulatedUser(get_intention("stack"), "stop", user_profile("exact"), rng=2)  # normal, 0.5 s ± 0.15 s
    delays = np.array([u.respond(SCENE, [t]).stop_time - reveal_time(1) for _ in range(N)])
    assert delays.min() >= 0
    # Folding at 0 is 3.3 sd away: the moments are those of the normal.
    assert abs(delays.mean() - 0.5) <= 4 * 0.15 / math.sqrt(N)
    assert abs(delays.std() - 0.15) <= 4 * 0.15 / math.sqrt(2 * (N - 1))


def test_lognormal_reaction_delay_statistics():
    t = traj(BAD_SECOND)
    u = user(delay="lognormal", delay_mean=0.7, delay_sd=0.35, seed=3)
    delays = np.array([u.respond(SCENE, [t]).stop_time - reveal_time(1) for _ in range(N)])
    assert delays.min() > 0
    assert abs(delays.mean() - 0.7) <= 4 * 0.35 / math.sqrt(N)
    s2 = math.log(1 + (0.35 / 0.7) ** 2)
    median = math.exp(math.log(0.7) - s2 / 2)
    assert within(int((delays < median).sum()), 0.5)
    assert np.mean(delays > 0.7 + 0.35) > np.mean(delays < 0.7 - 0.35)  # right-skewed


def no_stop_rate_of_the_model(u: SimulatedUser, t) -> float:
    h = u.signal.answer_at(t, None)
    return float(u.signal.likelihood(h, [t], u.judge, u.model)[0])


@pytest.mark.parametrize(
    "plan, stop",
    [
        (GOOD_STACK, {"false_stop": 0.2}),
        (GOOD_STACK, {"false_stop": 0.1, "lapse": 0.2}),
        (BAD_SECOND, {"missed_stop": 0.3}),
        (BAD_SECOND, {"missed_stop": 0.2, "lapse": 0.3, "late_tail": 0.5}),
        (BAD_SECOND, {"missed_stop": 0.3, "false_stop": 0.2}),
    ],
)
def test_no_stop_frequency_matches_the_stop_model(plan, stop):
    t = traj(plan)
    u = user(seed=4, **stop)
    expected = no_stop_rate_of_the_model(u, t)
    assert 0.05 < expected < 0.95  # the case really is noisy
    assert within(sum(not u.respond(SCENE, [t]).stopped for _ in range(N)), expected)


def test_false_stops_are_uniform_over_the_trajectory():
    t = traj(GOOD_STACK)
    u = user(false_stop=0.2, seed=3)
    times = [h.stop_time for h in (u.respond(SCENE, [t]) for _ in range(N)) if h.stopped]
    assert within(len(times), 0.2)
    assert 0 <= min(times) and max(times) <= t.duration
    # uniform on [0, duration]: mean in the middle, sd duration/√12
    assert abs(np.mean(times) / t.duration - 0.5) <= 4 * math.sqrt(1 / 12 / len(times))


def test_late_stops_land_anywhere_after_the_bad_step_starts():
    t = traj(BAD_SECOND)
    start = t.time_of(t.steps[1].start_tick)
    u = user(late_tail=1.0, seed=5)
    times = np.array([u.respond(SCENE, [t]).stop_time for _ in range(N)])
    assert times.min() >= start - 1e-9 and times.max() <= t.duration
    assert abs(times.mean() - (start + t.duration) / 2) <= 4 * (t.duration - start) / math.sqrt(12 * N)


def test_missed_bad_move_means_no_stop_even_with_a_later_bad_step():
    # Only the first move away counts: when it is missed the user does not wait for the next one.
    u = user(missed_stop=0.3, seed=4)
    t = traj(BAD_BOTH)
    answers = [u.respond(SCENE, [t]) for _ in range(N)]
    assert within(sum(not h.stopped for h in answers), 0.3)
    assert all(t.step_at(h.stop_time) == 0 for h in answers if h.stopped)


def test_deterministic_from_the_seed():
    t = traj(BAD_SECOND)

    def run(seed):
        u = user(seed=seed, false_stop=0.3, missed_stop=0.2, delay_sd=0.2)
        return [u.respond(SCENE, [t]).stop_time for _ in range(30)]

    assert run(9) == run(9)
    assert run(9) != run(10)


def test_new_scene_when_the_intention_cannot_be_shown():
    scene = Scene(objects=["red block", "red bowl", "blue bowl"])  # stack needs two blocks
    t = kinematic_trajectory(scene, 0, [])
    h = user().respond(scene, [t])
    assert h.new_scene and h.stop_time is None


def test_respond_needs_one_trajectory():
    t = traj([])
    with pytest.raises(ValueError, match="one trajectory"):
        user().respond(SCENE, [t, t])


@pytest.mark.parametrize("stop", [
    {"delay_sd": 0.2, "false_stop": 0.3, "missed_stop": 0.3},
    {"delay_sd": 0.2, "lapse": 0.5},
    {"delay_sd": 0.2, "late_tail": 0.5},
])
def test_the_random_stream_does_not_depend_on_what_was_shown(stop):
    # same seed, different trajectories: the generator must end in the same state, so that a
    # user's later answers do not depend on what earlier queries showed
    states = set()
    for plan in (GOOD_STACK, BAD_SECOND, BAD_BOTH):
        u = user(seed=8, **stop)
        t = traj(plan)
        for _ in range(20):
            u.respond(SCENE, [t])
        states.add(str(u.rng.bit_generator.state))
    assert len(states) == 1
