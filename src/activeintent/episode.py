"""One episode (design.md §2; protocol.py): the only module that knows the learner, the
executor, the env and the user.

    success_at[0] = score(learner's prior answer)
    while signals < K:
        scene  = learner.design_scene()            (else sampled; logged)
        z, y   = learner.estimate(scene)            eq. (1)(2) or (5)(6)
        τ      = executor(y) → env
        h      = user.respond(τ)                    every answer is one signal
        r      = learner.observe(h, τ)              eq. (3)(4) for stop methods
        success_at[k] = score(learner's current answer on the test scenes)

Observers subscribe to events: ``started``, ``shown`` (a query's τ are ready), ``answered``
(a round's record), ``tested`` (a test scene run in physics), ``scored`` (success after
signal k) and ``finished``. The live table,
the web session and the records writer are observers. How the test scenes are scored is
scoring.py's (:class:`~activeintent.scoring.Scorer`); when, this loop's.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Protocol

import numpy as np

from activeintent.envs import Env
from activeintent.intentions.base import Intention
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.llm.base import ModelError
from activeintent.protocol import (
    FREE_NEW_SCENES,
    draw_test_scenes,
    sample_round_scene,
)
from activeintent.provenance import provenance
from activeintent.records import EpisodeRecorder, EpisodeResult, RoundLog, TestLog
from activeintent.scoring import Scorer
from activeintent.signals import Answer, answer_kind_from_dump
from activeintent.spec import ProtocolConfig
from activeintent.world import Scene, Skill, WorldState, describe_plan
from activeintent.world.trajectory import Trajectory

__all__ = ["Episode", "EpisodeResult", "RoundLog", "TestLog", "answer_kind_from_dump"]  # records: re-exported


class User(Protocol):
    def respond(self, scene: Scene, trajectories: list[Trajectory]) -> Answer: ...


class PlanExecutor(Protocol):
    def to_plan(self, instruction: str, state: WorldState) -> Any: ...


@dataclass
class _Clock:
    split: dict[str, float] = field(default_factory=lambda: {
        "env_s": 0.0, "learner_s": 0.0, "executor_s": 0.0, "user_s": 0.0, "scoring_s": 0.0, "video_s": 0.0})

    def timed(self, key: str, fn: Callable, *args, **kwargs):
        start = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            self.split[key] += time.perf_counter() - start


class Episode:
    """Runs one episode. ``usage`` returns (calls, prompt tokens, completion tokens) of the
    models in use so the episode reports its own share; ``observers`` get its events."""

    def __init__(
        self,
        learner: Learner,
        intention: Intention,
        user: User,
        executor: PlanExecutor,
        env: Env,
        protocol: ProtocolConfig | None = None,
        observers: list[Any] | None = None,
        usage: Callable[[], tuple[int, int, int]] | None = None,
        model_time: Callable[[], float] | None = None,
        extra_config: dict | None = None,
        out_dir: str | Path | None = None,
        show_final: Literal["first", "first-feasible", "learner-showable"] | None = None,
    ):
        self.learner, self.intention, self.user = learner, intention, user
        # Opt-in (the web study): after the final scoring, emit ``final_shown`` with one test
        # scene's physics execution, the first test scene ("first"), the first on which the
        # intention can be shown at all ("first-feasible", an assigned rule) or the first the
        # learner's own belief expects to show its goals on ("learner-showable", a free rule: the
        # learner's P(shown) ≥ 0.5; the first scene for learners without a belief). Not part of
        # the records: None (the default) changes nothing.
        self.show_final = show_final
        self.executor, self.env = executor, env
        self.protocol = protocol or ProtocolConfig()
        self.observers = list(observers or [])
        self.usage = usage or (lambda: (0, 0, 0))
        self.model_time = model_time or (lambda: 0.0)
        self.extra_config = extra_config or {}
        self.out = Path(out_dir) if out_dir else None
        if self.out is not None and not any(isinstance(o, EpisodeRecorder) for o in self.observers):
            self.observers.insert(0, EpisodeRecorder(self.out))
        self.seeds = self.protocol.seeds
        self.clock = _Clock()
        self.scoring = Scorer(self)

    def emit(self, event: str, *args) -> None:
        for obs in self.observers:
            handler = getattr(obs, event, None)
            if handler is not None:
                handler(*args)

    # -- grounding y ---------------------------------------------------------------------------
    def _plan(self, goal: str, state: WorldState) -> tuple[list[Skill], str | None]:
        result = self.clock.timed("executor_s", self.executor.to_plan, goal, state)
        failure = result.failure.feedback_text() if result.failure else None
        return list(result.plan), failure

    def executor_calls(self) -> list[dict]:
        """The executor's model calls since the last drain (y → program/plan), if it keeps them."""
        drain = getattr(self.executor, "drain_transcript", None)
        return drain() if drain is not None else []

    def ground(self, ask: Callable[[Scene, WorldState], Estimate], scene: Scene, state: WorldState
               ) -> tuple[Estimate, list[list[Skill]], list[str | None]]:
        """z, y from the learner and y turned into plans; y that cannot be grounded is sent back
        ("I failed to generate the goal…") up to max_goal_retries times, and so are two
        showcases that became one motion when the learner takes that back (``showcases_alike``)."""
        for attempt in range(self.protocol.max_goal_retries + 1):
            est = self.clock.timed("learner_s", ask, scene, state)
            if est.plans is not None:
                return est, [list(p) for p in est.plans], [None] * len(est.plans)
            plans, failures = [], []
            for goal in est.goals:
                plan, failure = self._plan(goal, state)
                plans.append(plan)
                failures.append(failure)
            bad = [(g, f) for g, f in zip(est.goals, failures, strict=False) if f]
            last = attempt == self.protocol.max_goal_retries
            if bad and not last:
                for goal, failure in bad:
                    self.learner.execution_failed(goal, failure or "")
                continue
            alike = len(plans) == 2 and plans[0] == plans[1]
            if not alike or last or not self.learner.showcases_alike(list(est.goals)):
                return est, plans, failures
        raise AssertionError("unreachable")

    def video(self, traj: Trajectory, name: str, stop_time: float | None = None) -> None:
        if self.out is None or not self.env.renders or traj.renderer is None:
            return
        # lazy: PyBullet loads only for envs that render
        from activeintent.sim.video import export_video

        self.clock.timed("video_s", export_video, traj, self.out / f"{name}.gif", fps=self.protocol.video_fps,
                         stop_time=stop_time)

    # -- the loop ------------------------------------------------------------------------------
    def run(self) -> EpisodeResult:
        start = time.perf_counter()
        calls0, model0 = self.usage(), self.model_time()
        cfg = self.protocol
        self.emit("started", self)
        scene_rng = np.random.default_rng(self.seeds.scenes)
        layout_rng = np.random.default_rng(self.seeds.layouts)
        tests = draw_test_scenes(self.seeds.test, self.protocol.test_scenes + self.protocol.test_pool)
        logs: list[RoundLog] = []
        success_at: list[float | None] = []
        test_logs: list[TestLog] = []
        signals = free_new = 0
        done_at = None
        error = None
        after_new_scene = False
        try:
            if cfg.curve or cfg.budget == 0 or not self.learner.asks:
                rate, test_logs = self.scoring.score(0, tests, final=cfg.budget == 0)
            else:  # slow learners (model calls) are scored at k = K only
                rate = None
            success_at.append(rate)
            while self.learner.asks and signals < cfg.budget:
                log = self._round(len(logs), scene_rng, layout_rng, after_new_scene)
                after_new_scene = log.answer.get("new_scene", False)
                free = after_new_scene and cfg.new_scene == "free" and free_new < FREE_NEW_SCENES
                free_new += free
                log.counted = not free
                signals += log.counted
                log.signals_used = signals
                logs.append(log)
                self.emit("answered", log)
                if log.done and done_at is None:
                    done_at = signals
                if log.counted and (cfg.curve or signals == cfg.budget):
                    rate, test_logs = self.scoring.score(signals, tests, final=signals == cfg.budget)
                    success_at.append(rate)
                elif log.counted:
                    success_at.append(None)
                if log.done and cfg.stop_when_done and self.learner.may_finish:
                    break
            if signals < cfg.budget:
                # No more signals come (zero-signal baseline, or the learner finished): its answer
                # stands for the rest of the budget, and is scored on the whole pool for k = K.
                success_at += [rate] * (cfg.budget - len(success_at))
                rate, test_logs = self.scoring.score(signals, tests, final=True)
                success_at.append(rate)
        except ModelError as err:
            error = f"model error after {signals} signals: {err}"
            success_at += [None] * (cfg.budget + 1 - len(success_at))
        result = self._result(start, calls0, model0, logs, success_at, test_logs, signals, done_at, error)
        self.emit("finished", result)
        return result

    def _result(self, start: float, calls0: tuple[int, int, int], model0: float, logs: list[RoundLog],
                success_at: list[float | None], test_logs: list[TestLog], signals: int, done_at: int | None,
                error: str | None) -> EpisodeResult:
        """The episode's record (summary.json, a results line) from what the loop gathered."""
        cfg = self.protocol
        calls1 = self.usage()
        physics_scored = [t for t in test_logs if t.feasible and t.success_physics is not None]
        split = {k: round(v, 3) for k, v in self.clock.split.items()}
        split["model_s"] = round(self.model_time() - model0, 3)  # inside learner_s / executor_s
        final_at = next((i for i, t in enumerate(test_logs) if t.feasible), 0)
        result = EpisodeResult(
            method=self.learner.name,
            intention=self.intention.name,
            seed=cfg.seed,
            test_seed=self.seeds.test,
            env=self.env.name,
            budget=cfg.budget,
            new_scene=cfg.new_scene,
            success=success_at[-1] if error is None else None,
            success_at=success_at,
            success_physics=float(np.mean([t.success_physics for t in physics_scored])) if physics_scored else None,
            physics_disagreements=sum(t.success != t.success_physics for t in physics_scored) if physics_scored else None,
            test_scenes=cfg.test_scenes,
            test_pool=cfg.test_pool,
            test_excluded=sum(not t.feasible for t in test_logs),
            test_scored=sum(t.feasible for t in test_logs) if test_logs else None,
            signals_used=signals,
            answers=dict(Counter(answer_kind_from_dump(log.answer) for log in logs)),
            rounds_used=len(logs),
            done_at=done_at,
            final_z=test_logs[final_at].z if test_logs else "",
            final_goal=test_logs[final_at].goal if test_logs else "",
            final_scene=final_at if test_logs else None,
            retriever=self.learner.retriever,
            variant=getattr(self.learner, "variant", None),
            llm_calls=calls1[0] - calls0[0],
            prompt_tokens=calls1[1] - calls0[1],
            completion_tokens=calls1[2] - calls0[2],
            wall_s=round(time.perf_counter() - start, 3),
            time_split=split,
            tests=test_logs,
            learner_stats=self.learner.stats(),
            diagnostics=self.learner.diagnostics(),
            user=getattr(self.user, "parameters", lambda: {})(),
            error=error,
            config={"episode": cfg.model_dump(), **self.extra_config},
            provenance=provenance(),
        )
        return result

    def _round(self, index: int, scene_rng, layout_rng, after_new_scene: bool) -> RoundLog:
        t0 = dict(self.clock.split)
        scene, source = None, "learner"
        if after_new_scene and not self.learner.redesigns_after_new_scene:
            source = "sampled (the user asked for a new scene)"
        else:
            scene = self.clock.timed("learner_s", self.learner.design_scene)
            if scene is None:
                source = "sampled (the learner designs no scenes, or its choice was unusable)"
            elif after_new_scene:
                source = "learner (after a new-scene answer)"
        if scene is None:
            scene = sample_round_scene(scene_rng)
        layout_seed = int(layout_rng.integers(2**31))
        state = self.clock.timed("env_s", self.env.reset, scene, layout_seed)
        est, plans, failures = self.ground(self.learner.estimate, scene, state)
        labels = ["A", "B"] if len(plans) == 2 else ["y"] * len(plans)
        trajectories = []
        for i, plan in enumerate(plans):
            self.clock.timed("env_s", self.env.reset, scene, layout_seed)
            traj = self.clock.timed("env_s", self.env.execute, plan)
            trajectories.append(traj)
            failures[i] = failures[i] or ("; ".join(s.reason or "" for s in traj.failures) or None)
        self.emit("shown", index, scene, est, trajectories)
        h = self.clock.timed("user_s", self.user.respond, scene, trajectories)
        if self.protocol.video == "all":  # after the answer, so a stop can be marked where it came
            stop = getattr(h, "stop_time", None)
            for label, traj in zip(labels, trajectories, strict=True):
                self.video(traj, f"round{index + 1}_{label}", stop)
        record = RoundRecord(index=index, scene=scene, estimate=est, plans=plans, failures=failures, answer=h)
        r = self.clock.timed("learner_s", self.learner.observe, record, trajectories)
        return RoundLog(
            round=index + 1, scene=list(scene.objects), scene_source=source, layout_seed=layout_seed,
            z=est.z, goals=est.goals, labels=labels, plans=[describe_plan(p) for p in plans], failures=failures,
            executed=[t.moved_anything for t in trajectories], answer=h.model_dump(mode="json"), counted=True,
            signals_used=0, retrieved=r, retriever=self.learner.retriever, done=est.done, why=est.why,
            variant=getattr(self.learner, "variant", None),
            calls=self.learner.drain_transcript() + self.executor_calls(),
            timing={k: round(v - t0[k], 4) for k, v in self.clock.split.items()},
        )
