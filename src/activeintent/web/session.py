"""One participant's session: an episode in its own worker thread with a :class:`HumanUser`.

Each session owns a folder ``out/<session-id>/`` holding exactly what a simulated run saves
(``summary.json``, ``rounds.jsonl``, GIFs) plus the WebM videos shown in the browser and
``events.jsonl`` (every raw UI event with client and server timestamps). The episode, its
learner and its simulator (own PyBullet client) are built and used only in the worker thread.
"""

from __future__ import annotations

import json
import re
import secrets
import threading
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field

from activeintent.users.human import (
    AnswerRejected,
    HumanUser,
    Question,
    SessionCancelled,
    video_duration,
    video_frames,
)

SESSION_ID = re.compile(r"^[0-9a-f]{16}$")
# Only these files are ever served from a session folder.
SERVED_FILE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*\.(webm|gif)$")

Status = Literal["waiting-for-learner", "waiting-for-answer", "finished", "failed", "cancelled"]
# (seed, out_dir, user, observers) -> Episode; the session is one of the episode's observers
EpisodeBuilder = Callable[[int, Path, HumanUser, list[Any]], Any]


class StudyConfig(BaseModel):
    """What every session of one `activeintent serve` runs; participants cannot change it."""

    method: str
    signal: str = Field(description="the signal plug-in the study asks for (see activeintent.signals)")
    rounds: int = Field(ge=1, le=100, description="K: signals asked of each participant")
    intention: str | None = None
    show_estimate: bool = Field(True, description="show the learner's current estimate z")
    out_dir: Path = Path("out/web")
    seed: int = Field(0, description="session n (0, 1, …) runs with seed + n unless it asks for one")
    fps: int = Field(10, ge=1, le=60, description="frames per second of the videos")
    video_size: tuple[int, int] = Field((240, 240), description="width, height of the videos in pixels")
    answer_timeout: float | None = Field(1800.0, description="seconds to wait for one answer")
    max_sessions: int = Field(4, ge=1, description="sessions in progress at once")


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


class WebSession:
    def __init__(self, sid: str, seed: int, config: StudyConfig, builder: EpisodeBuilder, participant: str | None):
        self.id, self.seed, self.config, self.builder = sid, seed, config, builder
        self.participant = participant
        self.dir = (config.out_dir / sid).resolve()
        self.dir.mkdir(parents=True, exist_ok=False)
        self.created = time.time()
        self.user = HumanUser(config.signal, timeout=config.answer_timeout, present=self._present)
        self.estimate: str | None = None
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
    def start(self) -> None:
        (self.dir / "session.json").write_text(
            json.dumps(
                {
                    "id": self.id,
                    "seed": self.seed,
                    "participant": self.participant,
                    "created": self.created,
                    "study": json.loads(self.config.model_dump_json()),
                },
                indent=2,
            )
        )
        self.log_server("session_created", seed=self.seed, participant=self.participant)
        self._thread.start()

    def _run(self) -> None:
        episode = None
        try:
            episode = self.builder(self.seed, self.dir, self.user, [self])
            result = episode.run()
            if self._final_trajectory is not None:
                self.final_video = self._export(self._final_trajectory, "final", "final")
            self.result = json.loads(result.model_dump_json())
            if result.error:
                self.error = result.error
            self._status_override = "finished"
            self.log_server("session_finished", success=result.success, error=result.error)
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
            videos=[v.model_dump() for v in videos],
        )
        return videos

    # -- episode events (worker thread): the session observes the episode --------------------
    def shown(self, index: int, scene: Any, estimate: Any, trajectories: list[Any]) -> None:
        self.estimate = estimate.z

    def answered(self, log: Any) -> None:
        self.rounds.append(RoundInfo(round=log.round, answer=log.answer, z=log.z, signals_used=log.signals_used))
        if log.signals_used >= self.config.rounds:
            self.phase = "final"

    def tested(self, k: int, index: int, scene: Any, estimate: Any, traj: Any) -> None:
        if index == 0:  # the final attempt shown to the participant: the first test scene
            self._final_trajectory = traj
            self.estimate = estimate.z

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

    def state(self) -> dict:
        q = self.user.question
        status = self.status
        question = None
        if q is not None and status == "waiting-for-answer":
            question = {
                "round": q.round,
                "kind": self.config.signal,
                "scene": list(q.scene.objects),
                "videos": [v.model_dump() for v in (q.presented or [])],
            }
        return {
            "id": self.id,
            "method": self.config.method,
            "signal": self.config.signal,
            "status": status,
            "phase": self.phase,
            "rounds": self.config.rounds,
            "rounds_answered": len(self.rounds),
            "signals_used": self.signals_used,
            # the round the participant is on, as "round i of K"
            "progress": min(self.signals_used + 1, self.config.rounds),
            "question": question,
            "estimate": self.estimate if self.config.show_estimate else None,
            "final_video": self.final_video.model_dump() if self.final_video else None,
            "success": self.result["success"] if self.result else None,
            "error": self.error,
        }

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
