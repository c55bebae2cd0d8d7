"""HumanUser: the hand-over between the episode's thread and the person's answers; and the stop
signal's reading of its page's answer: a stop in the video mapped to the trajectory (the same h
a simulated stop user gives)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from activeintent.signals import AnswerRejected, ShownRound
from activeintent.signals.preference import PreferenceAnswer
from activeintent.signals.stop import StopAnswer, StopForm, StopSignal
from activeintent.users.human import HumanUser, SessionCancelled
from activeintent.web.videos import video_duration, video_frames
from activeintent.world import PutIn, Scene, WorldState
from activeintent.world.trajectory import StepRecord, Trajectory


def _trajectory(n_ticks: int = 181, dt: float = 1 / 60) -> Trajectory:
    """A 3 s log: idle, step 0 over ticks 20–90, step 1 over ticks 100–170, idle."""
    step_index = np.full(n_ticks, -1)
    step_index[20:91] = 0
    step_index[100:171] = 1
    state = WorldState(positions={"red block": (0.0, 0.0, 0.02), "red bowl": (0.1, 0.0, 0.0)})
    steps = [
        StepRecord(i, PutIn(block="red block", bowl="red bowl"), s, s + 10, e, True, None, state, state)
        for i, (s, e) in enumerate([(20, 90), (100, 170)])
    ]
    return Trajectory(
        scene=Scene(objects=["red block", "red bowl", "blue block"]),
        seed=0,
        dt=dt,
        object_names=["red block", "red bowl"],
        object_poses=np.zeros((n_ticks, 2, 7)),
        joint_positions=np.zeros((n_ticks, 7)),
        ee_pose=np.zeros((n_ticks, 7)),
        gripper_closed=np.zeros(n_ticks, dtype=bool),
        step_index=step_index,
        steps=steps,
    )


SCENE = Scene(objects=["red block", "red bowl", "blue block"])


def stop_answer(traj: Trajectory, t: float, fps: int) -> StopAnswer:
    """h the stop signal reads from its page's stop at media time t (first viewing, not ended);
    built without the form's own checks, so the signal's are the ones tested."""
    form = StopForm.model_construct(kind="stop", round=1, action="stop", time=t, viewing="first", client_ts=None)
    return StopSignal().from_web(form, ShownRound([traj], [video_duration(traj, fps)], fps))


def test_video_length_matches_frames_of_the_trajectory():
    traj = _trajectory()  # duration 3.0 s
    assert traj.duration == pytest.approx(3.0)
    assert video_frames(traj, 10) == 31  # frames at 0.0, 0.1, …, 3.0 s
    assert video_duration(traj, 10) == pytest.approx(3.1)
    odd = _trajectory(n_ticks=178)  # 2.95 s: frames at 0.0, …, 2.9 and the last tick
    assert video_frames(odd, 10) == 31 and video_duration(odd, 10) == pytest.approx(3.1)


@pytest.mark.parametrize("t,tick,frame", [(0.0, 0, 0), (0.05, 3, 0), (0.1, 6, 1), (0.35, 21, 3),
                                          (1.234, 74, 12), (1.6, 96, 16), (2.999, 180, 29), (3.0, 180, 30)])
def test_stop_maps_media_time_to_tick_and_frame(t, tick, frame):
    h = stop_answer(_trajectory(), t, fps=10)
    assert h.stop_time == pytest.approx(t)
    assert (h.tick, h.frame) == (tick, frame)
    assert h.stopped and not h.new_scene
    assert "step_index" not in h.model_dump()  # a person's stop is a time, not a step


def test_stop_on_the_last_frame_after_the_end_is_clipped_to_the_trajectory():
    traj = _trajectory()
    h = stop_answer(traj, 3.07, fps=10)  # the last frame stays on screen until 3.1 s
    assert h.stop_time == pytest.approx(3.0)
    assert h.tick == traj.n_ticks - 1
    assert h.frame == 30


@pytest.mark.parametrize("t", [-0.01, 3.2, float("nan"), float("inf"), -float("inf")])
def test_stop_outside_the_video_is_rejected(t):
    with pytest.raises(AnswerRejected, match="outside the video") as err:
        stop_answer(_trajectory(), t, fps=10)
    assert err.value.status == 422


def _respond_in_thread(user: HumanUser, trajectories):
    out: dict = {}

    def run():
        try:
            out["h"] = user.respond(SCENE, trajectories)
        except Exception as err:  # handed back to the test
            out["error"] = err

    thread = threading.Thread(target=run)
    thread.start()
    return thread, out


def test_preference_answer_is_handed_to_the_episode():
    presented = []
    user = HumanUser("preference", timeout=30, present=lambda q: presented.append(q.round) or "videos")
    thread, out = _respond_in_thread(user, [_trajectory(), _trajectory()])
    q = user.wait_question(10)
    assert q is not None and q.round == 1 and q.presented == "videos" and presented == [1]
    h = user.answer(1, lambda q: PreferenceAnswer(choice="A"))
    thread.join(10)
    assert out == {"h": h} and h.choice == "A"
    assert user.question is None


def test_answers_for_other_rounds_or_no_round_are_rejected_and_change_nothing():
    user = HumanUser("stop", timeout=30)
    with pytest.raises(AnswerRejected, match="no question is waiting") as err:
        user.answer(1, lambda q: StopAnswer())
    assert err.value.status == 409
    thread, out = _respond_in_thread(user, [_trajectory()])
    assert user.wait_question(10).round == 1
    for wrong in (0, 2, 7):
        with pytest.raises(AnswerRejected, match="waiting for round 1"):
            user.answer(wrong, lambda q: StopAnswer())
    with pytest.raises(AnswerRejected, match="outside the video"):
        user.answer(1, lambda q: stop_answer(q.trajectories[0], 99.0, 10))
    with pytest.raises(AnswerRejected, match="asks for stop answers"):
        user.answer(1, lambda q: PreferenceAnswer(choice="A"))
    assert user.question is not None and "h" not in out  # still waiting for a valid answer
    user.answer(1, lambda q: stop_answer(q.trajectories[0], 1.5, 10))
    thread.join(10)
    assert out["h"].tick == 90
    # the same round again (a replayed answer) is refused
    with pytest.raises(AnswerRejected, match="no question is waiting"):
        user.answer(1, lambda q: StopAnswer())


def test_timeout_and_cancel_end_the_wait():
    user = HumanUser("stop", timeout=0.05)
    with pytest.raises(SessionCancelled, match="no answer within"):
        user.respond(SCENE, [_trajectory()])
    with pytest.raises(AnswerRejected, match="has ended"):
        user.answer(1, lambda q: StopAnswer())

    user = HumanUser("preference", timeout=None)
    thread, out = _respond_in_thread(user, [_trajectory(), _trajectory()])
    assert user.wait_question(10) is not None
    user.cancel("the server stopped")
    thread.join(10)
    assert isinstance(out["error"], SessionCancelled) and "server stopped" in str(out["error"])


def test_wrong_number_of_trajectories_and_unknown_signal():
    with pytest.raises(ValueError, match="valid signals: preference, stop"):
        HumanUser("clicks")
    with pytest.raises(ValueError, match="shows 2 trajectories"):
        HumanUser("preference").respond(SCENE, [_trajectory()])
