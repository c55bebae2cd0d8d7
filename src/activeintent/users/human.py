"""A person gives the sparse signal h (through the web app instead of a simulated user).

The episode loop runs in a worker thread and calls :meth:`HumanUser.respond`, which hands the
round's trajectories τ to whoever presents them (the web session) and blocks until the person
answers, the wait times out, or the session is cancelled. Answers come from another thread
(an HTTP request) through :meth:`HumanUser.answer`; they must name the round they answer, so a
replayed or stale answer can never become another round's h.

What the person's page posts becomes h by the signal itself (``Signal.from_web``: e.g. the stop
signal maps a press at video time t to τ's time t, its tick and frame, as for a simulated user).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from activeintent.signals import Answer, AnswerRejected, Signal, get_signal
from activeintent.world import Scene
from activeintent.world.trajectory import Trajectory


class SessionCancelled(RuntimeError):
    """The session ended (cancelled, or the person did not answer in time) while the
    episode waited for h."""


@dataclass
class Question:
    """What the person is asked in one round: the scene and τ (two for preference, one for
    stop), plus whatever the presenter prepared for it (e.g. video URLs)."""

    round: int
    scene: Scene
    trajectories: list[Trajectory]
    presented: Any = None
    asked_at: float = field(default_factory=time.time)


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
