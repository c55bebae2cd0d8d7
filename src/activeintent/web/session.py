"""One participant's session: an episode in its own worker thread with a :class:`HumanUser`.

Each session owns a folder ``out/<session-id>/`` holding what a simulated run saves
(``summary.json``, ``rounds.jsonl``, GIFs) plus the WebM videos shown in the browser,
``events.jsonl`` (every raw UI event with client and server timestamps), ``session.json`` (the
study's configuration, rewritten with the final status when the session ends) and, once the
participant has answered it, ``questionnaire.json``. The episode, its learner and its simulator
(own PyBullet client) are built and used only in the worker thread.

Two study designs:

* **assigned-rule** (``StudyConfig.intention`` set): every participant is told the rule and
  the learner's final answer is scored against it (``success``, ``success_basis:
  "assigned-rule"``).
* **free-rule** (no intention): each participant teaches a rule of their own, which the server
  cannot know. The episode still carries the runner's default intention for its simulated
  parts, but nothing of it is shown or scored: ``summary.json`` says ``success: null``,
  ``success_basis: "none"``; the participant's own verdict is in ``questionnaire.json``.
"""

from __future__ import annotations

import json
import os
import re
import secrets
import threading
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, computed_field, model_validator

from activeintent.records import EpisodeRecorder, dumps
from activeintent.users.human import (
    AnswerRejected,
    HumanUser,
    Question,
    SessionCancelled,
    video_duration,
    video_frames,
)
from activeintent.web.errors import ApiError

SESSION_ID = re.compile(r"^[0-9a-f]{16}$")
# Only these files are ever served from a session folder.
SERVED_FILE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*\.(webm|gif)$")

Status = Literal["waiting-for-learner", "waiting-for-answer", "finished", "failed", "cancelled"]
# (seed, out_dir, user, observers) -> Episode; the session is one of the episode's observers
EpisodeBuilder = Callable[[int, Path, HumanUser, list[Any]], Any]


EstimateMode = Literal["hidden", "after-answer", "always"]
ESTIMATE_MODES: tuple[str, ...] = ("hidden", "after-answer", "always")
Design = Literal["assigned-rule", "free-rule"]


class StudyConfig(BaseModel):
    """What every session of one `activeintent serve` runs; participants cannot change it."""

    method: str
    signal: str = Field(description="the signal plug-in the study asks for (see activeintent.signals)")
    rounds: int = Field(ge=1, le=100, description="K: signals asked of each participant")
    intention: str | None = Field(
        None, description="the rule every participant is assigned (and success is scored against); "
        "None: each participant picks their own rule and success is not scored")
    intention_file: str | None = Field(None, description="the assigned rule from a file (path.py:NAME)")
    intention_description: str | None = Field(None, description="the assigned rule in words, as participants read it")
    show_estimate: EstimateMode = Field(
        "hidden", description="the learner's current guess z: never shown (hidden), shown between rounds "
        "after each answer (after-answer), or above the videos from round 2 on (always)")
    out_dir: Path = Path("out/web")
    seed: int = Field(0, description="session n (0, 1, …) runs with seed + n unless it asks for one")
    fps: int = Field(10, ge=1, le=60, description="frames per second of the videos")
    video_size: tuple[int, int] = Field((480, 480), description="width, height of the videos in pixels")
    answer_timeout: float | None = Field(1800.0, description="seconds to wait for one answer")
    max_sessions: int = Field(4, ge=1, description="sessions in progress at once")

    @computed_field  # type: ignore[prop-decorator]
    @property
    def design(self) -> Design:
        """assigned-rule when the study gives participants a rule, else free-rule."""
        return "assigned-rule" if self.intention or self.intention_file else "free-rule"

    @model_validator(mode="after")
    def _describe_rule(self) -> StudyConfig:
        if self.design == "assigned-rule" and self.intention_description is None:
            from activeintent.suites import resolve

            rule = resolve(None if self.intention_file else self.intention, self.intention_file)
            self.intention = rule.name
            self.intention_description = rule.description or rule.name
        if self.design == "free-rule":
            self.intention_description = None
        return self


class VideoInfo(BaseModel):
    label: str
    url: str
    file: str
    fps: int
    frames: int
    duration: float = Field(description="media length in seconds (frames / fps)")
    trajectory_duration: float


class RoundInfo(BaseModel):
    round: int
    answer: dict
    z: str | None = None
    signals_used: int = 0


CONFIDENCE_BASIS = "the learner's posterior probability of this guess among its hypotheses"


class Guess(BaseModel):
    """The learner's current guess z as a participant may see it."""

    z: str
    confidence: float | None = Field(None, ge=0, le=1, description="the learner's belief in z, where it has one")
    basis: str | None = Field(None, description="what the confidence is")
    answers: int = Field(description="answers of this participant the guess is based on")


def _belief_of(top: Any, z: str) -> float | None:
    """p of ``z`` in a belief snapshot's ``top`` list of (description, p) pairs."""
    if not isinstance(top, list | tuple):
        return None
    for item in top:
        if isinstance(item, list | tuple) and len(item) == 2 and item[0] == z and isinstance(item[1], int | float):
            return float(item[1])
    return None


def guess_of(estimate: Any, answers: int, belief_top: Any = None) -> Guess:
    """The guess of an :class:`~activeintent.learners.base.Estimate`. Bayesian learners say how
    much they believe z (``why.belief_before``, or the last belief snapshot of the round records
    for the final answer); other learners give no confidence."""
    why = getattr(estimate, "why", None) or {}
    before = why.get("belief_before") if isinstance(why, dict) else None
    p = _belief_of(before.get("top") if isinstance(before, dict) else None, estimate.z)
    if p is None:
        p = _belief_of(belief_top, estimate.z)
    return Guess(z=estimate.z, confidence=None if p is None else round(min(max(p, 0.0), 1.0), 4),
                 basis=None if p is None else CONFIDENCE_BASIS, answers=answers)


def scene_legend(objects: list[str]) -> list[dict]:
    """The scene's objects by name, with their colour (for the pages' colour-name legend)."""
    from activeintent.world import COLORS

    legend = []
    for name in objects:
        color, _, kind = name.partition(" ")
        rgb = COLORS.get(color)
        hex_ = "#" + "".join(f"{round(255 * c):02x}" for c in rgb) if rgb else None
        legend.append({"name": name, "color": color, "kind": kind, "hex": hex_})
    return legend


def study_summary(summary: dict, config: StudyConfig) -> dict:
    """``summary.json`` as the study reads it. An assigned-rule session is scored against the
    rule participants were given; a free-rule session is not scored at all (the episode's
    built-in intention was never the participant's), so every success field is null."""
    out = {**summary, "design": config.design}
    if config.design == "assigned-rule":
        out["success_basis"] = "assigned-rule"
        return out
    out.update(
        intention=None,
        success=None,
        success_basis="none",
        success_note="free-rule study: each participant chose their own rule, so success is not applicable; "
                     "the participant's own verdict is in questionnaire.json",
        success_at=[None for _ in summary.get("success_at", [])],
        success_physics=None,
        physics_disagreements=None,
        test_excluded=None,
        tests=[{**t, "feasible": None, "success": None, "success_physics": None} for t in summary.get("tests", [])],
    )
    return out


def write_json(path: Path, value: Any) -> None:
    """Write strict JSON atomically (a reader never sees half a file)."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(json.loads(dumps(value)), indent=2))
    os.replace(tmp, path)


class StudyRecorder(EpisodeRecorder):
    """The episode's own writer, except that ``summary.json`` is written as the study reads
    it (:func:`study_summary`): a free-rule session's file never holds a score."""

    def __init__(self, out: Path, config: StudyConfig):
        super().__init__(out)
        self.config = config
        self.summary: dict | None = None

    def finished(self, result) -> None:
        self.summary = study_summary(result.model_dump(mode="json"), self.config)
        write_json(self.out / "summary.json", self.summary)


class WebSession:
    def __init__(self, sid: str, seed: int, config: StudyConfig, builder: EpisodeBuilder, participant: str | None):
        self.id, self.seed, self.config, self.builder = sid, seed, config, builder
        self.participant = participant
        self.dir = (config.out_dir / sid).resolve()
        self.dir.mkdir(parents=True, exist_ok=False)
        self.created = time.time()
        self.user = HumanUser(config.signal, timeout=config.answer_timeout, present=self._present)
        self.estimate: str | None = None  # the learner's z of the question on screen (or the final one)
        self.guess: Guess | None = None  # the same, with its confidence
        self.final_guess: Guess | None = None
        self.final_scene: list[str] | None = None
        self.questionnaire: dict | None = None
        self.ended: float | None = None
        self._belief_top: Any = None  # the last belief snapshot of a Bayesian learner
        self._questionnaire_lock = threading.Lock()
        self.phase: Literal["rounds", "final"] = "rounds"
        self.rounds: list[RoundInfo] = []
        self.result: dict | None = None
        self.error: str | None = None
        self.final_video: VideoInfo | None = None
        self._final_trajectory: Any = None
        self._done = threading.Event()
        self._status_override: Status | None = None
        self._events_lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, name=f"session-{sid}", daemon=True)

    # -- lifecycle --------------------------------------------------------------------------
    def _write_session_file(self) -> None:
        """``session.json``: who, when, the study's configuration (design, rule, how z is
        shown, video size, …) and, once the session has ended, how it ended."""
        write_json(self.dir / "session.json", {
            "id": self.id,
            "seed": self.seed,
            "participant": self.participant,
            "created": self.created,
            "design": self.config.design,
            "show_estimate": self.config.show_estimate,
            "status": self.status,
            "ended": self.ended,
            "error": self.error,
            "study": json.loads(self.config.model_dump_json()),
        })

    def start(self) -> None:
        self._write_session_file()
        self.log_server("session_created", seed=self.seed, participant=self.participant,
                        design=self.config.design, show_estimate=self.config.show_estimate)
        self._thread.start()

    def _run(self) -> None:
        episode = None
        try:
            recorder = StudyRecorder(self.dir, self.config)
            episode = self.builder(self.seed, self.dir, self.user, [recorder, self])
            result = episode.run()
            if self._final_trajectory is not None:
                self.final_video = self._export(self._final_trajectory, "final", "final")
            self.result = recorder.summary or study_summary(json.loads(result.model_dump_json()), self.config)
            if result.error:
                self.error = result.error
            self._status_override = "finished"
            self.log_server("session_finished", success=self.result.get("success"),
                            success_basis=self.result.get("success_basis"), error=result.error)
        except SessionCancelled as err:
            self.error = str(err)
            self._status_override = "cancelled"
            self.log_server("session_cancelled", reason=str(err))
        except Exception as err:  # a crash in one session must not take the server down
            self.error = f"{type(err).__name__}: {err}"
            self._status_override = "failed"
            self.log_server("session_failed", error=self.error, traceback=traceback.format_exc())
        finally:
            if episode is not None:
                try:
                    episode.env.close()
                except Exception:
                    pass
            self.ended = time.time()
            try:
                self._write_session_file()
            except OSError:
                pass
            self._done.set()

    def cancel(self, reason: str) -> None:
        self.user.cancel(reason)

    def join(self, timeout: float | None = None) -> bool:
        return self._done.wait(timeout)

    @property
    def status(self) -> Status:
        if self._status_override is not None:
            return self._status_override
        return "waiting-for-answer" if self.user.question is not None else "waiting-for-learner"

    @property
    def active(self) -> bool:
        return not self._done.is_set()

    # -- the episode's hooks (worker thread) -----------------------------------------------
    def _export(self, traj: Any, name: str, label: str) -> VideoInfo:
        from activeintent.sim.video import export_video

        fps = self.config.fps
        export_video(traj, self.dir / f"{name}.webm", fps=fps, size=self.config.video_size)
        return VideoInfo(
            label=label,
            file=f"{name}.webm",
            url=f"/api/sessions/{self.id}/files/{name}.webm",
            fps=fps,
            frames=video_frames(traj, fps),
            duration=video_duration(traj, fps),
            trajectory_duration=traj.duration,
        )

    def _present(self, q: Question) -> list[VideoInfo]:
        if len(q.trajectories) == 2:
            names = [(f"round{q.round}_a", "A"), (f"round{q.round}_b", "B")]
        else:
            names = [(f"round{q.round}_y", "robot")]
        videos = [self._export(t, n, label) for t, (n, label) in zip(q.trajectories, names, strict=True)]
        self.log_server(
            "round_presented",
            round=q.round,
            scene=list(q.scene.objects),
            estimate=self.estimate,
            confidence=self.guess.confidence if self.guess else None,
            estimate_shown=self._guess_visible(self.guess),  # how: the study's show_estimate
            videos=[v.model_dump() for v in videos],
        )
        return videos

    # -- episode events (worker thread): the session observes the episode --------------------
    def shown(self, index: int, scene: Any, estimate: Any, trajectories: list[Any]) -> None:
        self.estimate = estimate.z
        self.guess = guess_of(estimate, answers=len(self.rounds))

    def answered(self, log: Any) -> None:
        self.rounds.append(RoundInfo(round=log.round, answer=log.answer, z=log.z, signals_used=log.signals_used))
        for call in reversed(log.calls or []):
            if isinstance(call, dict) and "top" in call:  # a Bayesian learner's belief after the answer
                self._belief_top = call["top"]
                break
        if log.signals_used >= self.config.rounds:
            self.phase = "final"

    def tested(self, k: int, index: int, scene: Any, estimate: Any, traj: Any) -> None:
        if index == 0:  # the final attempt shown to the participant: the first test scene
            self._final_trajectory = traj
            self.final_scene = list(scene.objects)
            self.estimate = estimate.z
            self.final_guess = guess_of(estimate, answers=len(self.rounds), belief_top=self._belief_top)

    @property
    def signals_used(self) -> int:
        return self.rounds[-1].signals_used if self.rounds else 0

    # -- the person's side (request threads) -----------------------------------------------
    def answer(self, round: int, make: Callable[[Question], Any], client: dict | None = None):
        if not self.active:
            raise AnswerRejected(f"session {self.id} is {self.status}; it takes no more answers", status=409)
        h = self.user.answer(round, make)
        self.log_server("answer", round=round, answer=h.model_dump(mode="json"), client=client)
        return h

    def _guess_visible(self, guess: Guess | None) -> bool:
        # never the learner's prior: a guess is shown only once it rests on an answer
        return self.config.show_estimate != "hidden" and guess is not None and guess.answers >= 1

    def visible_guess(self) -> Guess | None:
        """The guess the participant may see now: the current question's (while it waits for
        an answer) or the final one (once finished); None when the study hides it."""
        status = self.status
        guess = self.guess if status == "waiting-for-answer" else self.final_guess if status == "finished" else None
        return guess if self._guess_visible(guess) else None

    def state(self) -> dict:
        q = self.user.question
        status = self.status
        question = None
        if q is not None and status == "waiting-for-answer":
            objects = list(q.scene.objects)
            question = {
                "round": q.round,
                "kind": self.config.signal,
                "scene": objects,
                "legend": scene_legend(objects),
                "videos": [v.model_dump() for v in (q.presented or [])],
            }
        guess = self.visible_guess()
        finished = status == "finished"
        return {
            "id": self.id,
            "method": self.config.method,
            "signal": self.config.signal,
            "design": self.config.design,
            "intention": self.config.intention if self.config.design == "assigned-rule" else None,
            "intention_description": self.config.intention_description,
            "show_estimate": self.config.show_estimate,
            "status": status,
            "phase": self.phase,
            "rounds": self.config.rounds,
            "rounds_answered": len(self.rounds),
            "signals_used": self.signals_used,
            # the round the participant is on, as "round i of K"
            "progress": min(self.signals_used + 1, self.config.rounds),
            "question": question,
            "estimate": guess.model_dump() if guess else None,
            "final_video": self.final_video.model_dump() if self.final_video and finished else None,
            "final_legend": scene_legend(self.final_scene) if self.final_scene and finished else None,
            "success": self.result.get("success") if self.result else None,
            "success_basis": self.result.get("success_basis") if self.result else None,
            "questionnaire": {
                "open": not self.active and self.questionnaire is None,
                "submitted": self.questionnaire is not None,
                "asks_final_attempt": self.final_video is not None and finished,
            },
            "error": self.error,
        }

    # -- the end-of-session questionnaire (request threads) ------------------------------------
    def submit_questionnaire(self, answers: dict) -> dict:
        """Keep the participant's answers in ``questionnaire.json`` (once; after the episode)."""
        if self.active:
            raise ApiError(409, "conflict", f"session {self.id} is {self.status}: the questionnaire comes "
                           "after the robot's final attempt")
        asks = self.final_video is not None and self.status == "finished"
        if asks and answers.get("final_attempt") is None:
            raise ApiError(422, "invalid_answer", "final_attempt is required: did the final attempt do what "
                           "you wanted? 'yes', 'partly' or 'no'")
        if not asks and answers.get("final_attempt") is not None:
            raise ApiError(422, "invalid_answer", f"session {self.id} ended without a final attempt "
                           f"({self.status}); leave final_attempt out")
        with self._questionnaire_lock:
            if self.questionnaire is not None or (self.dir / "questionnaire.json").exists():
                raise ApiError(409, "already_submitted", f"the questionnaire of session {self.id} is already "
                               "answered; the answers are kept as they were")
            record = {
                "session": self.id,
                "participant": self.participant,
                "design": self.config.design,
                "intention": self.config.intention if self.config.design == "assigned-rule" else None,
                "session_status": self.status,
                "submitted": time.time(),
                **answers,
            }
            write_json(self.dir / "questionnaire.json", record)
            self.questionnaire = record
        self.log_server("questionnaire_submitted", final_attempt=answers.get("final_attempt"),
                        rule_chars=len(answers.get("rule") or ""), comments_chars=len(answers.get("comments") or ""))
        return record

    # -- raw UI events ---------------------------------------------------------------------
    def log_events(self, events: list[dict]) -> int:
        now = time.time()
        with self._events_lock, (self.dir / "events.jsonl").open("a") as f:
            for e in events:
                f.write(json.dumps({"server_ts": now, "source": "client", **e}) + "\n")
        return len(events)

    def log_server(self, type: str, **data: Any) -> None:
        record = {"server_ts": time.time(), "source": "server", "type": type, **data}
        with self._events_lock, (self.dir / "events.jsonl").open("a") as f:
            f.write(json.dumps(record, default=str) + "\n")

    def file(self, name: str) -> Path | None:
        """A file of this session's folder that may be served, or None."""
        if not SERVED_FILE.match(name):
            return None
        path = (self.dir / name).resolve()
        if path.parent != self.dir or not path.is_file():
            return None
        return path


class SessionManager:
    """All sessions of one server; each isolated in its own folder and thread."""

    def __init__(self, config: StudyConfig, builder: EpisodeBuilder):
        self.config, self.builder = config, builder
        self._sessions: dict[str, WebSession] = {}
        self._lock = threading.Lock()
        self._count = 0

    def create(self, participant: str | None = None, seed: int | None = None) -> WebSession:
        with self._lock:
            active = sum(1 for s in self._sessions.values() if s.active)
            if active >= self.config.max_sessions:
                raise AnswerRejected(
                    f"{active} sessions are in progress (limit {self.config.max_sessions}); try again later",
                    status=503,
                )
            if seed is None:
                seed = self.config.seed + self._count
            self._count += 1
            sid = secrets.token_hex(8)
            while sid in self._sessions or (self.config.out_dir / sid).exists():
                sid = secrets.token_hex(8)
            session = WebSession(sid, seed, self.config, self.builder, participant)
            self._sessions[sid] = session
        session.start()
        return session

    def get(self, sid: str) -> WebSession | None:
        if not SESSION_ID.match(sid):
            return None
        with self._lock:
            return self._sessions.get(sid)

    def all(self) -> list[WebSession]:
        with self._lock:
            return list(self._sessions.values())

    def shutdown(self, timeout: float = 10.0) -> None:
        sessions = self.all()
        for s in sessions:
            s.cancel("the server stopped")
        deadline = time.monotonic() + timeout
        for s in sessions:
            s.join(max(0.0, deadline - time.monotonic()))
