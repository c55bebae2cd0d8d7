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

import hashlib
import hmac
import json
import os
import re
import secrets
import threading
import time
import traceback
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, computed_field, field_validator, model_validator

from activeintent.envs import ENVS
from activeintent.protocol import FORMAT_VERSION
from activeintent.records import EpisodeRecorder, dumps
from activeintent.signals import AnswerRejected, ShownRound
from activeintent.spec import RunSpec
from activeintent.suites import resolve
from activeintent.users.human import HumanUser, Question, SessionCancelled
from activeintent.web.basics import VIDEO_SIZE, EstimateMode, parse_video_size, write_json
from activeintent.web.errors import ApiError
from activeintent.web.live import LiveExport
from activeintent.web.questionnaire import Questionnaire
from activeintent.web.study import Assigner, button_order
from activeintent.web.videos import SessionVideos, VideoInfo
from activeintent.world import COLORS

SESSION_ID = re.compile(r"^[0-9a-f]{16}$")
KEY_ID_CHARS = 16  # of the key's SHA-256: enough to tell browsers apart, useless to forge one
# Only these files are ever served from a session folder.
SERVED_FILE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*\.(webm|mp4|gif)$")

def _record_viewing(v: dict, event: str) -> dict:
    """Apply a video event to its viewing record (first ``ready`` / ``ended`` times, replays:
    a replay only after the end); a copy of the record after it. Called under the events lock."""
    if event == "replay" and v["ended"] is None:
        raise ApiError(409, "conflict", "a replay comes after the first viewing has ended")
    if event in ("ready", "ended") and v[event] is None:
        v[event] = time.time()
    if event == "replay":
        v["replays"] += 1
    return dict(v)


def signal_page(signal: str) -> str:
    """The path of a signal's answer page in the web app."""
    return f"/signal/{signal}"


# enrolled: agreed and given a key, the episode not started yet (it starts at the page's Start)
Status = Literal["enrolled", "waiting-for-learner", "waiting-for-answer", "finished", "failed", "cancelled"]
# (seed, out_dir, user, observers) -> Episode; the session is one of the episode's observers
EpisodeBuilder = Callable[[int, Path, HumanUser, list[Any]], Any]


Design = Literal["assigned-rule", "free-rule"]


class StudyConfig(BaseModel):
    """What every session of one `activeintent serve` runs; participants cannot change it.

    ``run`` is the episode each session runs (method, K, env, the assigned rule in its user
    section, models); session n runs with its seed + n unless it asks for one. The rest is the
    study's own: the signal's page, what participants read and see, and the server's limits."""

    run: RunSpec
    signal: str = Field(description="the signal plug-in the study asks for (see activeintent.signals)")
    intention_name: str | None = Field(
        None, description="the assigned rule's name (filled from run.user); None: each participant picks their "
        "own rule and success is not scored")
    intention_description: str | None = Field(None, description="the assigned rule in words, as participants read it")
    show_estimate: EstimateMode = Field(
        "hidden", description="the learner's current guess z: never shown (hidden), shown between rounds "
        "after each answer (after-answer), or above the videos from round 2 on (always)")
    out_dir: Path = Path("out/web")
    fps: int = Field(10, ge=1, le=60, description="frames per second of the videos")
    video_size: tuple[int, int] = Field(VIDEO_SIZE, description="width, height of the videos in pixels (at the "
                                        "default every block is at least 40 px wide)")
    answer_timeout: float | None = Field(1800.0, description="seconds to wait for one answer")
    max_sessions: int = Field(4, ge=1, description="sessions in progress at once")
    render_workers: int = Field(default_factory=lambda: min(2, os.cpu_count() or 1), ge=1, le=32,
                                description="processes that draw the videos' frames (shared by all sessions)")

    @computed_field  # type: ignore[prop-decorator]
    @property
    def design(self) -> Design:
        """assigned-rule when the study gives participants a rule, else free-rule."""
        return "assigned-rule" if self.run.user.intention or self.run.user.intention_file else "free-rule"

    @property
    def budget(self) -> int:
        """K: the signals asked of each participant."""
        return self.run.protocol.budget

    @field_validator("video_size")
    @classmethod
    def _video_size_in_range(cls, size: tuple[int, int]) -> tuple[int, int]:
        return parse_video_size(f"{size[0]}x{size[1]}")  # the CLI's rule: 64-2048 pixels a side

    @field_validator("run")
    @classmethod
    def _people_watch_physics(cls, run: RunSpec) -> RunSpec:
        ENVS.check(run.env.name)
        if run.protocol.budget < 1:
            raise ValueError("a study asks each participant for at least one signal (budget ≥ 1)")
        return run

    @model_validator(mode="after")
    def _describe_rule(self) -> StudyConfig:
        if self.design == "assigned-rule" and (self.intention_name is None or self.intention_description is None):
            who = self.run.user
            rule = resolve(None if who.intention_file else who.intention, who.intention_file)
            self.intention_name = rule.name
            if self.intention_description is None:
                self.intention_description = rule.description or rule.name
        if self.design == "free-rule":
            self.intention_name = self.intention_description = None
        return self


class RoundInfo(BaseModel):
    round: int
    answer: dict
    z: str | None = None
    signals_used: int = 0


CONFIDENCE_BASIS = "the learner's posterior probability of this guess among its hypotheses"
EXPECTED_SUCCESS_BASIS = ("the learner's expected probability that this attempt does what you want "
                          "(its belief over rules, on this table)")


def new_session_key() -> tuple[str, str]:
    """A session key (the cookie's value, 256 random bits) and its SHA-256 (what is kept)."""
    key = secrets.token_urlsafe(32)
    return key, key_digest(key)


def key_digest(key: str) -> str:
    return hashlib.sha256(key.encode("utf-8", "surrogatepass")).hexdigest()


class Enrolment(BaseModel):
    """How a session came to be: its condition (study file) and who it is, from the URL."""

    condition: str = Field("single", description="the study file's condition ('single': serve without one)")
    slot: int = Field(0, description="participants of this condition before this one")
    number: int = Field(0, description="participants of the study before this one")
    again: bool = Field(False, description="a participant ID seen before, given its earlier condition")
    pid: str | None = Field(None, description="the participant ID from the URL (?pid= or PROLIFIC_PID=)")
    study_id: str | None = Field(None, description="STUDY_ID from the URL")
    prolific_session_id: str | None = Field(None, description="SESSION_ID from the URL")
    consented: float | None = Field(None, description="server time the consent was given (None: no consent asked)")
    button_order: list[str] = Field(default_factory=list, description="the answer buttons, in the order shown")
    key_id: str | None = Field(None, description="the start of the SHA-256 of the session key cookie given to "
                               "the browser that started the session (the only one that may answer)")


class Completion(BaseModel):
    """What a participant gets once the questionnaire is sent (from the study file)."""

    code: str | None = None
    redirect_url: str | None = None
    redirect_after_s: float | None = None


class Guess(BaseModel):
    """The learner's current guess z as a participant may see it."""

    z: str
    confidence: float | None = Field(None, ge=0, le=1, description="the learner's belief in z, where it has one")
    basis: str | None = Field(None, description="what the confidence is")
    kind: Literal["posterior", "expected_success"] | None = Field(
        None, description="posterior: the belief in z; expected_success: the final attempt's expected success")
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
    for the final answer) or, for the final answer, how likely its attempt is to succeed
    (``why.expected_success``); other learners give no confidence."""
    why = getattr(estimate, "why", None) or {}
    why = why if isinstance(why, dict) else {}
    before = why.get("belief_before")
    p = _belief_of(before.get("top") if isinstance(before, dict) else None, estimate.z)
    basis = CONFIDENCE_BASIS
    if p is None:
        p = _belief_of(belief_top, estimate.z)
    expected = why.get("expected_success")
    if p is None and isinstance(expected, int | float) and not isinstance(expected, bool):
        # the final answer names z by description while the snapshots name rules: its own
        # expected success is the confidence it does report
        p, basis = float(expected), EXPECTED_SUCCESS_BASIS
    return Guess(z=estimate.z, confidence=None if p is None else round(min(max(p, 0.0), 1.0), 4),
                 basis=None if p is None else basis, answers=answers,
                 kind=None if p is None else "posterior" if basis == CONFIDENCE_BASIS else "expected_success")


def scene_legend(objects: list[str]) -> list[dict]:
    """The scene's objects by name, with their colour (for the pages' colour-name legend)."""
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


class StudyRecorder(EpisodeRecorder):
    """The episode's own writer, except that ``summary.json`` is written as the study reads
    it (:func:`study_summary`): a free-rule session's file never holds a score."""

    def __init__(self, out: Path, config: StudyConfig, answered_by: Callable[[int], dict | None] | None = None):
        super().__init__(out)
        self.config = config
        self.answered_by = answered_by or (lambda round: None)
        self.summary: dict | None = None

    def answered(self, log) -> None:
        # as the episode's own line, plus who gave the answer (participant, key, address)
        line = {"format": FORMAT_VERSION, **log.model_dump(mode="json"), "answered_by": self.answered_by(log.round)}
        with (self.out / "rounds.jsonl").open("a") as f:
            f.write(dumps(line) + "\n")

    def finished(self, result) -> None:
        self.summary = study_summary(result.model_dump(mode="json"), self.config)
        write_json(self.out / "summary.json", self.summary)


class WebSession:
    def __init__(self, sid: str, seed: int, config: StudyConfig, builder: EpisodeBuilder, participant: str | None,
                 enrolment: Enrolment | None = None, completion: Completion | None = None,
                 key_sha256: str | None = None):
        self.id, self.seed, self.config, self.builder = sid, seed, config, builder
        self.participant = participant
        self.enrolment = enrolment or Enrolment()
        # the SHA-256 of the session key cookie (never the key itself); None: nobody may answer
        self._key_sha256 = key_sha256
        self._answered_by: dict[int, dict] = {}  # round -> who gave its accepted answer
        self.completion = completion
        # per round: when the first viewing was started (Ready) and ended, and replays after it
        self._viewing: dict[int, dict] = {}
        self._final_viewing = {"ready": None, "ended": None, "replays": 0}  # the final attempt's video
        self.final_scene_index: int | None = None
        self.final_scene_feasible: bool | None = None
        self.dir = (config.out_dir / sid).resolve()
        self.dir.mkdir(parents=True, exist_ok=False)
        self.created = time.time()
        self.user = HumanUser(config.signal, timeout=config.answer_timeout, present=self._present)
        self.estimate: str | None = None  # the learner's z of the question on screen (or the final one)
        self.guess: Guess | None = None  # the same, with its confidence
        self.final_guess: Guess | None = None
        self.final_scene: list[str] | None = None
        self.questionnaire = Questionnaire(self.dir, sid)
        self.ended: float | None = None
        self._belief_top: Any = None  # the last belief snapshot of a Bayesian learner
        self.phase: Literal["rounds", "final"] = "rounds"
        self.rounds: list[RoundInfo] = []
        self.result: dict | None = None
        self.error: str | None = None
        self.final_video: VideoInfo | None = None
        self._final_trajectory: Any = None
        self.videos = SessionVideos(sid, self.dir, config.fps, config.video_size, config.render_workers)
        self._done = threading.Event()
        self._status_override: Status | None = None
        self._events_lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, name=f"session-{sid}", daemon=True)
        self.begun = False  # the episode runs (Start pressed); before: enrolled, holding no slot
        self._start_lock = threading.Lock()

    # -- lifecycle --------------------------------------------------------------------------
    def _write_session_file(self) -> None:
        """``session.json``: who, when, the study's configuration (design, rule, how z is
        shown, video size, …) and, once the session has ended, how it ended."""
        write_json(self.dir / "session.json", {
            "id": self.id,
            "seed": self.seed,
            "participant": self.participant,
            **self.enrolment.model_dump(),
            "created": self.created,
            "design": self.config.design,
            "show_estimate": self.config.show_estimate,
            # the final attempt's table: its index among the test scenes, and whether the
            # assigned rule can be shown on it at all (None: free rule, nothing is known)
            "final_scene": self.final_scene,
            "final_scene_index": self.final_scene_index,
            "final_scene_feasible": self.final_scene_feasible,
            "status": self.status,
            "ended": self.ended,
            "error": self.error,
            "study": json.loads(self.config.model_dump_json()),
        })

    def start(self) -> None:
        with self._start_lock:
            if self.begun or self._done.is_set():
                return
            self.begun = True
        self._write_session_file()
        self.log_server("session_created", seed=self.seed, participant=self.participant,
                        design=self.config.design, show_estimate=self.config.show_estimate,
                        **self.enrolment.model_dump())
        self._thread.start()

    def _run(self) -> None:
        episode = None
        try:
            recorder = StudyRecorder(self.dir, self.config, answered_by=self._answered_by.get)
            episode = self.builder(self.seed, self.dir, self.user, [recorder, self])
            result = episode.run()
            self.videos.finish()
            if self._final_trajectory is not None:
                self.final_video = self.videos.export_whole(self._final_trajectory, "final", "final")
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
            self.videos.settle()  # no file left half written when it ends
            self.ended = time.time()
            try:
                self._write_session_file()
            except OSError:
                pass
            self._done.set()

    def cancel(self, reason: str) -> None:
        with self._start_lock:
            if not self.begun and not self._done.is_set():  # enrolled only: nothing runs
                self.error = reason
                self._status_override = "cancelled"
                self.ended = time.time()
                self._done.set()
                return
        self.user.cancel(reason)

    def join(self, timeout: float | None = None) -> bool:
        return self._done.wait(timeout)

    @property
    def status(self) -> Status:
        if self._status_override is not None:
            return self._status_override
        if not self.begun:
            return "enrolled"
        return "waiting-for-answer" if self.user.question is not None else "waiting-for-learner"

    @property
    def active(self) -> bool:
        """Not ended yet (enrolled or running)."""
        return not self._done.is_set()

    @property
    def running(self) -> bool:
        """Its episode runs: it holds a slot of the server's and its client's."""
        return self.begun and not self._done.is_set()

    # -- the episode's hooks (worker thread) -----------------------------------------------
    def live_export(self, name: str) -> LiveExport | None:
        """The export still writing the file ``name``, or None (absent or complete)."""
        return self.videos.live(name)

    def _present(self, q: Question) -> list[VideoInfo]:
        """The round's videos, shown as soon as each can start playing (``web.live``)."""
        videos = self.videos.round(q.round, q.trajectories)
        self.log_server(
            "round_presented",
            round=q.round,
            scene=list(q.scene.objects),
            estimate=self.estimate,
            confidence=self.guess.confidence if self.guess else None,
            estimate_shown=self.guess_visible(self.guess),  # how: the study's show_estimate
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
        if log.signals_used >= self.config.budget:
            self.phase = "final"

    def tested(self, k: int, index: int, scene: Any, estimate: Any, traj: Any) -> None:
        if index == 0 and self.final_scene_index is None:  # episodes without final_shown: the first test scene
            self._set_final(index, scene, estimate, traj, None)

    def final_shown(self, index: int, scene: Any, estimate: Any, traj: Any, feasible: bool) -> None:
        """The final attempt shown to the participant (see ``Episode.show_final``)."""
        self._set_final(index, scene, estimate, traj, feasible if self.config.design == "assigned-rule" else None)
        self.log_server("final_attempt", scene=self.final_scene, index=index, feasible=self.final_scene_feasible)

    def _set_final(self, index: int, scene: Any, estimate: Any, traj: Any, feasible: bool | None) -> None:
        self._final_trajectory = traj
        self.final_scene = list(scene.objects)
        self.final_scene_index, self.final_scene_feasible = index, feasible
        self.estimate = estimate.z
        self.final_guess = guess_of(estimate, answers=len(self.rounds), belief_top=self._belief_top)

    @property
    def signals_used(self) -> int:
        return self.rounds[-1].signals_used if self.rounds else 0

    # -- the person's side (request threads) -----------------------------------------------
    def holds_key(self, keys: Iterable[str]) -> bool:
        """Whether one of ``keys`` (the request's key cookies) is this session's key."""
        if self._key_sha256 is None:
            return False
        return any(hmac.compare_digest(key_digest(k), self._key_sha256) for k in keys)

    def answered_by(self, address: str | None) -> dict:
        """Who gives an answer now: the session's participant (the link's pid or the typed
        code), the key they proved (its id) and the address the request came from."""
        return {"participant": self.participant, "key": self.enrolment.key_id, "address": address}

    def answer(self, round: int, make: Callable[[Question], Any], client: dict | None = None,
               by: dict | None = None):
        if not self.active:
            raise AnswerRejected(f"session {self.id} is {self.status}; it takes no more answers", status=409)

        def made(q: Question):
            h = make(q)
            # under the user's lock, so only the answer that is taken records who gave it (the
            # episode may write the round before this call returns)
            self._answered_by[q.round] = by
            return h

        try:
            h = self.user.answer(round, made)
        except AnswerRejected as err:
            # a stop after the video's end is kept on record, as refused (other bad answers
            # change nothing saved)
            if err.code == "after_video_end":
                self.log_server("stop_after_end", round=round, reason=str(err), client=client, answered_by=by)
            raise
        self.log_server("answer", round=round, answer=h.model_dump(mode="json"), client=client, answered_by=by)
        return h

    def shown_round(self, q: Question) -> ShownRound:
        """What the person was shown in question ``q``, for the signal to read their answer."""
        return ShownRound(trajectories=q.trajectories, video_lengths=[v.duration for v in q.presented or []],
                          fps=self.config.fps, viewing=self.viewing(q.round))

    # -- what the participant did with the round's video (request threads) --------------------
    def viewing(self, round: int) -> dict:
        return dict(self._viewing.get(round) or {"ready": None, "ended": None, "replays": 0})

    def video_event(self, round: int, event: str, media_time: float | None = None) -> dict:
        """``ready`` (the first viewing starts), ``ended`` (it has played to its end) or
        ``replay`` (a replay starts; only after the end) for the round on screen."""
        q = self.user.question
        if q is None or q.round != round or self.status != "waiting-for-answer":
            raise ApiError(409, "conflict", f"round {round} is not on screen in session {self.id}")
        with self._events_lock:
            out = _record_viewing(self._viewing.setdefault(round, {"ready": None, "ended": None, "replays": 0}), event)
        self.log_server(f"video_{event}", round=round, media_time=media_time, replays=out["replays"])
        return out

    def final_video_event(self, event: str, media_time: float | None = None) -> dict:
        """The final attempt's video: ``ready`` (it starts), ``ended`` (played to its end) or
        ``replay``. The questionnaire opens only after ``ended`` (:meth:`submit_questionnaire`)."""
        if not self.asks_final_attempt:
            raise ApiError(409, "conflict", f"session {self.id} is {self.status}: there is no final attempt to watch")
        with self._events_lock:
            out = _record_viewing(self._final_viewing, event)
        self.log_server(f"final_video_{event}", media_time=media_time, replays=out["replays"])
        return out

    def guess_visible(self, guess: Guess | None) -> bool:
        # never the learner's prior: a guess is shown only once it rests on an answer
        return self.config.show_estimate != "hidden" and guess is not None and guess.answers >= 1

    @property
    def asks_final_attempt(self) -> bool:
        """Whether the questionnaire asks about the robot's final attempt (it was shown)."""
        return self.final_video is not None and self.status == "finished"

    def submit_questionnaire(self, answers: dict, by: dict | None = None) -> dict:
        """Keep the participant's answers in ``questionnaire.json`` (once; after the episode)."""
        about = {"session": self.id, "participant": self.participant, "condition": self.enrolment.condition,
                 "design": self.config.design, "intention": self.config.intention_name}
        if self.asks_final_attempt:
            with self._events_lock:
                viewed = dict(self._final_viewing)
            if viewed["ended"] is None:
                raise ApiError(409, "final_video_not_watched", f"session {self.id}: the questions about the final "
                               "attempt open once its video has played to its end")
            # what the server saw, in place of the page's own word
            answers = {**answers, "final_video_watched": "replayed" if viewed["replays"] else "ended",
                       "final_video_server_seconds": round(viewed["ended"] - (viewed["ready"] or viewed["ended"]), 3)}
        record = self.questionnaire.submit(answers, status=self.status, active=self.active,
                                           asks_final_attempt=self.asks_final_attempt, about=about, by=by)
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
    """All sessions of one server; each isolated in its own folder and thread.

    ``conditions`` (a study file's, by name: their StudyConfig and builder) are assigned to new
    participants in a balanced way (:class:`activeintent.web.study.Assigner`, persisted in
    ``OUT/assignment.json``); without them every session runs ``config`` as condition
    ``single``. ``study`` is the study file (consent, completion code, …) or None."""

    def __init__(self, config: StudyConfig, builder: EpisodeBuilder,
                 conditions: dict[str, tuple[StudyConfig, EpisodeBuilder]] | None = None, study: Any = None):
        self.config, self.builder, self.study = config, builder, study
        self.conditions = conditions or {"single": (config, builder)}
        self._sessions: dict[str, WebSession] = {}
        self._lock = threading.Lock()
        self.assigner = Assigner(list(self.conditions), seed=study.assignment_seed if study else 0,
                                 path=config.out_dir / "assignment.json")

    def create(self, participant: str | None = None, seed: int | None = None, pid: str | None = None,
               study_id: str | None = None, prolific_session_id: str | None = None,
               consent: bool | None = None, key_sha256: str | None = None, start: bool = True) -> WebSession:
        """A new session. ``key_sha256``: the SHA-256 of the key the browser that asked for it
        was given (:func:`new_session_key`); only requests carrying that key may answer.
        ``start=False`` only enrols it (the start page's agreement): its condition is the one
        the assignment would give now, but it is counted, given its seed and its episode
        started only by :meth:`begin` (the page's Start)."""
        study = self.study
        if study is not None and study.require_pid and pid is None:
            raise ApiError(422, "pid_required", "this study needs a participant ID from its link "
                           "(?pid=… or ?PROLIFIC_PID=…); please open the link you were given")
        if study is not None and consent is not True:
            raise ApiError(422, "consent_required", "the session starts only after the participant "
                           "agrees to the consent text (consent: true)")
        with self._lock:
            if start:
                self._check_room()
            condition = self.assigner.peek(pid)
            config, builder = self.conditions[condition]
            sid = secrets.token_hex(8)
            while sid in self._sessions or (self.config.out_dir / sid).exists():
                sid = secrets.token_hex(8)
            enrolment = Enrolment(
                condition=condition, pid=pid, study_id=study_id, prolific_session_id=prolific_session_id,
                consented=time.time() if consent else None,
                key_id=key_sha256[:KEY_ID_CHARS] if key_sha256 else None)
            completion = Completion(code=study.completion_code, redirect_url=study.redirect_url,
                                    redirect_after_s=study.redirect_after_s) if study else None
            session = WebSession(sid, -1 if seed is None else seed, config, builder,
                                 participant if pid is None else pid,
                                 enrolment=enrolment, completion=completion, key_sha256=key_sha256)
            session.seed_given = seed is not None
            self._sessions[sid] = session
        if start:
            self.begin(session)
        return session

    def _check_room(self) -> None:
        running = sum(1 for s in self._sessions.values() if s.running)
        if running >= self.config.max_sessions:
            raise AnswerRejected(
                f"{running} sessions are in progress (limit {self.config.max_sessions}); try again later",
                status=503,
            )

    def begin(self, session: WebSession) -> WebSession:
        """Start an enrolled session's episode: it is counted in its condition now (the one it
        was told of), gets its seed and button order, and runs."""
        study = self.study
        with self._lock:
            if session.begun or not session.active:
                return session
            self._check_room()
            e = session.enrolment
            got = self.assigner.assign(e.pid, condition=e.condition)
            if got.condition != e.condition:  # a returning pid keeps its earlier condition
                session.config, session.builder = self.conditions[got.condition]
                session.user = HumanUser(session.config.signal, timeout=session.config.answer_timeout,
                                         present=session._present)
            config = session.config
            if not getattr(session, "seed_given", False):
                # persisted: a restarted server does not repeat seeds
                session.seed = config.run.protocol.seed + got.number
            session.enrolment = e.model_copy(update={
                **got.model_dump(),
                "button_order": button_order(config.signal, got.slot,
                                             study.counterbalance_buttons if study else True)})
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
