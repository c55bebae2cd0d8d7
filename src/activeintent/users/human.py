"""A person gives the sparse signal h (through the web app instead of a simulated user).

The episode loop runs in a worker thread and calls :meth:`HumanUser.respond`, which hands the
round's trajectories τ to whoever presents them (the web session) and blocks until the person
answers, the wait times out, or the session is cancelled. Answers come from another thread
(an HTTP request) through :meth:`HumanUser.answer`; they must name the round they answer, so a
replayed or stale answer can never become another round's h.

The clicker's stop time is mapped from the video to the trajectory exactly as a simulated stop
user's is: video frame k shows trajectory time k / fps, so a stop at media time t (seconds) is
the trajectory time t, its log tick ``traj.tick_at(t)``, frame ``floor(t * fps)`` and skill
the skill index is not part of h: a person's stop is only a time.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from activeintent.signals import Answer, Signal, get_signal
from activeintent.signals.stop import StopAnswer
from activeintent.world import Scene
from activeintent.world.trajectory import Trajectory


class SessionCancelled(RuntimeError):
    """The session ended (cancelled, or the person did not answer in time) while the
    episode waited for h."""


class AnswerRejected(ValueError):
    """An answer that cannot be taken: ``status`` is the HTTP-like code a server should give
    (404 nothing asked, 409 wrong round or state, 422 malformed)."""

    def __init__(self, message: str, status: int = 409):
        super().__init__(message)
        self.status = status


@dataclass
class Question:
    """What the person is asked in one round: the scene and τ (two for preference, one for
    stop), plus whatever the presenter prepared for it (e.g. video URLs)."""

    round: int
    scene: Scene
    trajectories: list[Trajectory]
    presented: Any = None
    asked_at: float = field(default_factory=time.time)


def video_frames(traj: Trajectory, fps: int) -> int:
    """Frames of the exported video of τ: one per 1/fps s from 0, plus the last tick when the
    duration is not a whole number of frames (``activeintent.sim.video.frame_times``)."""
    from activeintent.sim.video import frame_times

    return len(frame_times(traj, fps))


def video_duration(traj: Trajectory, fps: int) -> float:
    """Media length in seconds of the exported video: each frame is shown for 1/fps s."""
    return video_frames(traj, fps) / fps


def stop_answer(traj: Trajectory, t: float, fps: int) -> StopAnswer:
    """h for a stop pressed at video media time ``t`` (seconds).

    Raises :class:`AnswerRejected` (422) when t is not a finite time inside the video. The
    last frame stays on screen for 1/fps s past the trajectory's end, so t is clipped to the
    trajectory's duration for the trajectory time.
    """
    length = video_duration(traj, fps)
    if not isinstance(t, int | float) or not math.isfinite(t) or t < 0 or t > length + 1e-6:
        raise AnswerRejected(
            f"stop time {t!r} s is outside the video (valid: 0 to {length:.3f} s)", status=422
        )
    stop_time = min(float(t), traj.duration)
    return StopAnswer(stop_time=stop_time, tick=traj.tick_at(stop_time),
                      frame=int(math.floor(stop_time * fps + 1e-9)))




class HumanUser:
    """The user protocol of :class:`activeintent.episode.Episode`, answered by a person.

    ``present(question)`` runs in the episode's thread before the question is shown (the web
    session exports the videos there) and its return value is kept as ``question.presented``.
    ``timeout`` (seconds) bounds the wait for one answer; None waits until cancelled.
    """

    def __init__(
        self,
        signal: Signal | str,
        timeout: float | None = 1800.0,
        present: Callable[[Question], Any] | None = None,
    ):
        self.sig = get_signal(signal) if isinstance(signal, str) else signal
        self.signal = self.sig.name
        self.timeout = timeout
        self.present = present
        self._cond = threading.Condition()
        self._question: Question | None = None
        self._answer: Answer | None = None
        self._rounds = 0
        self._cancelled: str | None = None

    # -- the episode's side ----------------------------------------------------------------
    def respond(self, scene: Scene, trajectories: list[Trajectory]) -> Answer:
        expected = self.sig.shows
        if len(trajectories) != expected:
            raise ValueError(f"a {self.signal} round shows {expected} trajectories, got {len(trajectories)}")
        question = Question(round=self._rounds + 1, scene=scene, trajectories=list(trajectories))
        if self.present is not None:
            question.presented = self.present(question)
        deadline = None if self.timeout is None else time.monotonic() + self.timeout
        with self._cond:
            if self._cancelled:
                raise SessionCancelled(self._cancelled)
            self._rounds = question.round
            self._question, self._answer = question, None
            self._cond.notify_all()
            while self._answer is None and not self._cancelled:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    self._cancelled = f"no answer within {self.timeout:g} s in round {question.round}"
                    break
                self._cond.wait(left)
            answer, self._answer, self._question = self._answer, None, None
            self._cond.notify_all()
            if answer is None:
                raise SessionCancelled(self._cancelled or "cancelled")
            return answer

    # -- the person's side (any thread) ----------------------------------------------------
    @property
    def question(self) -> Question | None:
        """The question waiting for an answer, or None while the learner works."""
        with self._cond:
            return self._question

    @property
    def cancelled(self) -> str | None:
        with self._cond:
            return self._cancelled

    def wait_question(self, timeout: float) -> Question | None:
        """Block until a question is waiting (or ``timeout`` s pass); used by tests and polling."""
        with self._cond:
            self._cond.wait_for(lambda: self._question is not None or self._cancelled, timeout)
            return self._question

    def answer(self, round: int, make: Callable[[Question], Answer]) -> Answer:
        """Answer round ``round``; ``make(question)`` builds h from the question (it may raise
        :class:`AnswerRejected`). Atomic: a rejected answer changes nothing."""
        with self._cond:
            if self._cancelled:
                raise AnswerRejected(f"the session has ended: {self._cancelled}", status=409)
            q = self._question
            if q is None:
                raise AnswerRejected(
                    f"no question is waiting (round {round} was answered, or the learner is "
                    "still preparing the next round)",
                    status=409,
                )
            if round != q.round:
                raise AnswerRejected(
                    f"this answer is for round {round} but the session is waiting for round {q.round}",
                    status=409,
                )
            h = make(q)
            if h.signal != self.signal:
                raise AnswerRejected(f"this session asks for {self.signal} answers, not {h.signal}", status=422)
            self._answer, self._question = h, None
            self._cond.notify_all()
            return h

    def cancel(self, reason: str = "cancelled") -> None:
        with self._cond:
            if not self._cancelled:
                self._cancelled = reason
            self._cond.notify_all()
