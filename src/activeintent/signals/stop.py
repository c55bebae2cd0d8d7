"""The ``stop`` signal: one trajectory τ; h = the time the person pressed stop, or None
(watched to the end without objection).

Observation model (users sample from it, learners evaluate it, each with their own
parameters): under intention z the person notices the first step of τ that moves away from
z once its destination is visible — at the step's reveal time plus ``visible_after`` of the
rest of the step — and presses stop after a reaction delay (normal or log-normal). A share
``late_tail`` of stops lands anywhere later; a bad move is missed with ``missed_stop``; a
stop for no reason comes with ``false_stop`` at a uniform time; λ mixes in a uniform answer.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from activeintent.signals.base import Answer, AnswerRejected, ShownRound, Signal, WebForm
from activeintent.world.trajectory import Trajectory

EXPORT_FPS = 10  # videos are exported at 10 frames per second: frame = floor(t · fps)


class StopAnswer(Answer):
    """h for one τ: ``stop_time`` in seconds of τ (None = no stop); ``tick``/``frame`` locate it
    in the log and in the exported video. No step index: a person's stop is only a time."""

    signal: Literal["stop"] = "stop"
    stop_time: float | None = Field(None, ge=0)
    tick: int | None = Field(None, ge=0)
    frame: int | None = Field(None, ge=0)

    @property
    def stopped(self) -> bool:
        return self.stop_time is not None

    def _describe(self) -> str:
        if self.stop_time is None:
            return "the user watched to the end without stopping the robot"
        return f"the user stopped the robot at t = {self.stop_time:.2f} s"

    def _kind(self) -> str:
        return "no_stop" if self.stop_time is None else "stop"


class StopForm(WebForm):
    """The stop page's answer: a stop (with the video's time), no stop, or a new scene."""

    logged: ClassVar[tuple[str, ...]] = ("client_ts", "time", "viewing")

    kind: Literal["stop"]
    action: Literal["stop", "no_stop", "new_scene"]
    time: float | None = Field(None, allow_inf_nan=False,
                               description="for action 'stop': the video's currentTime in seconds")
    viewing: Literal["first", "replay"] = Field(
        "first", description="for action 'stop': during the first viewing or a replay after it")


class StopModel(BaseModel):
    """Parameters of the stop model (a user's true ones, or a learner's assumption)."""

    model_config = ConfigDict(extra="forbid")

    delay: Literal["normal", "lognormal"] = Field("normal", description="reaction-delay distribution")
    delay_mean: float = Field(0.5, ge=0, description="s from the bad move being visible to the press")
    delay_sd: float = Field(0.3, ge=0)
    visible_after: float = Field(0.0, ge=0, le=1, description="share of the step after its reveal before a person sees it")
    late_tail: float = Field(0.1, ge=0, le=1, description="share of stops anywhere after the bad step starts")
    false_stop: float = Field(0.05, ge=0, lt=1, description="P(stop although nothing moved away)")
    missed_stop: float = Field(0.05, ge=0, lt=1, description="P(no stop although a step moved away)")
    lapse: float = Field(0.02, ge=0, lt=1, description="λ: probability of a uniformly random answer")


def _times(traj: Trajectory, m: StopModel) -> tuple[np.ndarray, np.ndarray]:
    """Per step: the time its move becomes visible to the person, and its start time."""
    reveal = np.array([traj.time_of(s.reveal_tick) for s in traj.steps], float)
    end = np.array([traj.time_of(s.end_tick) for s in traj.steps], float)
    start = np.array([traj.time_of(s.start_tick) for s in traj.steps], float)
    return reveal + m.visible_after * np.maximum(end - reveal, 0.0), start


def _delay_density(x: np.ndarray, m: StopModel) -> np.ndarray:
    sd = max(m.delay_sd, 1e-3)
    if m.delay == "normal":
        return np.exp(-0.5 * ((x - m.delay_mean) / sd) ** 2) / (sd * math.sqrt(2 * math.pi))
    s2 = math.log(1 + (sd / max(m.delay_mean, 1e-3)) ** 2)
    mu = math.log(max(m.delay_mean, 1e-3)) - s2 / 2
    xp = np.maximum(x, 1e-9)
    return np.where(x > 0, np.exp(-((np.log(xp) - mu) ** 2) / (2 * s2)) / (xp * math.sqrt(2 * math.pi * s2)), 0.0)


def _delay_sample(m: StopModel, rng: np.random.Generator) -> float:
    if m.delay_sd == 0:
        return m.delay_mean
    if m.delay == "normal":
        return abs(float(rng.normal(m.delay_mean, m.delay_sd)))  # folded: no negative reactions
    s2 = math.log(1 + (m.delay_sd / max(m.delay_mean, 1e-3)) ** 2)
    return float(rng.lognormal(math.log(max(m.delay_mean, 1e-3)) - s2 / 2, math.sqrt(s2)))


class StopSignal(Signal):
    name = "stop"
    shows = 1
    Answer = StopAnswer
    Model = StopModel
    page_folder = "pages"
    page = "stop.html"
    how = "stop-how.html"
    page_assets = ("stop.js",)
    WebForm = StopForm
    buttons = ("no_stop", "new_scene")  # the Stop button stays where it is: a reaction, not a choice

    def learner_model(self) -> StopModel:
        # People react after the bad move shows, never before, with right-skewed delays: a
        # log-normal (mean 0.9 s, sd 0.6 s) keeps a late press from being read as a later step.
        return StopModel(delay="lognormal", delay_mean=0.9, delay_sd=0.6)

    def _one(self, shown: list[Trajectory]) -> Trajectory:
        if len(shown) != 1:
            raise ValueError(f"a stop query shows one trajectory τ; got {len(shown)}")
        return shown[0]

    def answer_at(self, traj: Trajectory, t: float | None, fps: int = EXPORT_FPS) -> StopAnswer:
        """The answer for a press at time t (clipped to τ), with its tick and the frame of τ's
        video at ``fps`` (frame k shows time k / fps)."""
        if t is None:
            return StopAnswer()
        t = float(min(max(t, 0.0), traj.duration))
        return StopAnswer(stop_time=t, tick=traj.tick_at(t), frame=int(math.floor(t * fps + 1e-9)))

    def from_web(self, form: StopForm, shown: ShownRound) -> StopAnswer:
        """A stop is a moment inside the video (its media time t; the last frame stays on screen
        1/fps s past τ's end, so t maps to min(t, τ's duration)), not at or after the video's end
        and not in a first viewing the page reported ended (a late key press)."""
        if form.action == "new_scene":
            if form.time is not None:
                raise AnswerRejected("action 'new_scene' takes no 'time'", status=422)
            return self.new_scene()
        if form.action == "no_stop":
            if form.time is not None:
                raise AnswerRejected("action 'no_stop' takes no 'time'", status=422)
            return StopAnswer()
        t, traj, length = form.time, self._one(shown.trajectories), shown.video_lengths[0]
        if t is None:
            raise AnswerRejected("action 'stop' needs 'time': the video time in seconds", status=422)
        if not math.isfinite(t) or t < 0 or t > length + 1e-6:
            raise AnswerRejected(f"stop time {t!r} s is outside the video (valid: 0 to {length:.3f} s)", status=422)
        if t >= length - 1e-9:
            raise AnswerRejected(f"stop time {t:.3f} s is at or after the end of the video ({length:.3f} s): the "
                                 "video had ended, so this is not a stop; answer no_stop or stop during a replay",
                                 status=422, code="after_video_end")
        if form.viewing == "first" and shown.viewing["ended"] is not None:
            raise AnswerRejected("the first viewing of this video had ended before this stop; stop during a "
                                 "replay (viewing: 'replay') or answer no_stop", status=422, code="after_video_end")
        if form.viewing == "replay" and not shown.viewing["replays"]:
            raise AnswerRejected("viewing 'replay' but no replay of this round was started", status=422)
        return self.answer_at(traj, t, shown.fps)

    def sample(self, shown, judge, model: StopModel, rng) -> StopAnswer:
        traj = self._one(shown)
        away = int(judge.first_away(traj)[0])
        # The same draws for every answer, so user noise streams stay aligned across methods
        # whatever was shown; the events are exclusive, as in ``likelihood``.
        u_event, u_tail, u_lapse, u_coin = rng.random(4)
        t_false, t_any, t_late = rng.uniform(0.0, 1.0, 3)
        delay = _delay_sample(model, rng)
        end = max(traj.duration, 1e-6)
        if u_lapse < model.lapse:
            return self.answer_at(traj, t_any * end if u_coin < 0.5 else None)
        if u_event < model.false_stop:
            return self.answer_at(traj, t_false * end)
        if away < 0 or u_event < model.false_stop + model.missed_stop:
            return StopAnswer()
        visible, start = _times(traj, model)
        if u_tail < model.late_tail:
            return self.answer_at(traj, start[away] + t_late * max(end - start[away], 0.0))
        return self.answer_at(traj, float(visible[away]) + delay)

    def likelihood(self, answer: StopAnswer, shown, judge, model: StopModel) -> np.ndarray:
        traj = self._one(shown)
        away = np.asarray(judge.first_away(traj))
        has = away >= 0
        span = max(traj.duration, 1e-3) + model.delay_mean + 3 * model.delay_sd  # stops may land after the end
        if answer.stop_time is None:
            base = np.where(has, model.missed_stop, 1 - model.false_stop)
            return (1 - model.lapse) * base + model.lapse / 2
        visible, start = _times(traj, model)
        k = np.where(has, away, 0)
        v = visible[k] if len(visible) else np.zeros(len(away))
        s = start[k] if len(start) else np.zeros(len(away))
        t = answer.stop_time
        timely = _delay_density(t - v, model)
        tail = np.where(t >= s, 1.0 / np.maximum(span - s, 1e-3), 0.0)
        caught = (1 - model.late_tail) * timely + model.late_tail * tail
        base = model.false_stop / span + np.where(has, (1 - model.false_stop - model.missed_stop) * caught, 0.0)
        return (1 - model.lapse) * base + model.lapse / (2 * span)

    def predictive(self, shown, judge, model: StopModel) -> np.ndarray:
        """[n, steps + 1]: P(stop caused by step j), P(no stop)."""
        traj = self._one(shown)
        away = np.asarray(judge.first_away(traj))
        n = max(len(traj.steps), 1)
        p = np.zeros((len(away), n + 1))
        has = away >= 0
        p[:, :n] = model.false_stop / n
        p[has, away[has]] += 1 - model.false_stop - model.missed_stop
        p[has, n] += model.missed_stop
        p[~has, n] += 1 - model.false_stop
        lapse = np.full(n + 1, model.lapse / (2 * n))  # as in likelihood: half stop somewhere, half no stop
        lapse[n] = model.lapse / 2
        return (1 - model.lapse) * p + lapse
