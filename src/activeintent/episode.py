"""One episode (design.md §2): K feedback rounds, then a final test on fresh scenes.

for round in 1..K:
    scene  = learner.design_scene()        (else sampled; logged)
    z, y   = learner.estimate(scene)        eq. (1)(2) or (5)(6)
    τ      = executor(y) → simulator
    h      = user.respond(τ)
    r      = learner.observe(h, τ)          eq. (3)(4) for stop methods
final: a fresh scene feasible for the hidden intention; z, y; executed; success = intention holds.

This is the only module that knows the learner, the executor, the simulator and the user.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from pydantic import BaseModel, Field

from activeintent.intentions.base import Intention
from activeintent.learners.base import Estimate, Learner, RoundRecord
from activeintent.llm.base import ModelError
from activeintent.signals import PreferenceFeedback, StopFeedback
from activeintent.sim.trajectory import Trajectory
from activeintent.world import Scene, Skill, WorldState, apply_plan, describe_plan, sample_scene


class EpisodeConfig(BaseModel):
    rounds: int = Field(5, ge=1, le=100, description="K: feedback signals the user gives at most")
    seed: int = 0
    test_scenes: int = Field(1, ge=1, le=50, description="fresh scenes the final answer is tested on")
    max_new_scenes: int = Field(3, ge=0, description="'new scene' answers allowed on top of K")
    max_goal_retries: int = Field(1, ge=0, description="re-asks when y cannot be turned into motion")
    video_fps: int = 10
    save_videos: bool = True
    track_progress: bool = Field(False, description="after each round, test the current estimate (symbolically)")


class User(Protocol):
    signal: str

    def respond(self, scene: Scene, trajectories: list[Trajectory]) -> PreferenceFeedback | StopFeedback: ...


class PlanExecutor(Protocol):
    def to_plan(self, instruction: str, state: WorldState) -> Any: ...


@dataclass
class EpisodeSeeds:
    """Every random choice of an episode flows from one seed. Trial t of every method gets the
    same seeds, so methods are compared on identical scenes and user noise."""

    scenes: int
    layouts: int
    user: int
    learner: int
    test: int

    @classmethod
    def from_seed(cls, seed: int) -> EpisodeSeeds:
        kids = np.random.SeedSequence(seed).spawn(5)
        return cls(*(int(k.generate_state(1)[0]) for k in kids))


class RoundLog(BaseModel):
    round: int
    scene: list[str]
    scene_source: str
    layout_seed: int
    preference: str
    goals: list[str]
    plans: list[str]
    failures: list[str | None]
    feedback: dict
    retrieved: str | None
    retriever: str | None
    done: bool
    progress_success: float | None = None
    signals_used: int = 0  # signals given so far, this round included
    calls: list[dict] = Field(default_factory=list)
    timing: dict[str, float] = Field(default_factory=dict)


class TestLog(BaseModel):
    scene: list[str]
    preference: str
    goal: str
    plan: str
    failure: str | None
    success: bool
    score: float
    calls: list[dict] = Field(default_factory=list)


class EpisodeResult(BaseModel):
    method: str
    intention: str
    seed: int
    success: bool
    success_rate: float
    rounds_used: int
    signals_used: int
    final_preference: str
    final_goal: str
    retriever: str | None
    llm_calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    wall_s: float = 0.0
    time_split: dict[str, float] = Field(default_factory=dict)
    per_round_success: list[float] = Field(default_factory=list)
    tests: list[TestLog] = Field(default_factory=list)
    learner_stats: dict = Field(default_factory=dict)
    error: str | None = None
    config: dict = Field(default_factory=dict)


@dataclass
class _Clock:
    split: dict[str, float] = field(default_factory=lambda: {"sim_s": 0.0, "render_s": 0.0, "model_s": 0.0})

    def timed(self, key: str, fn: Callable, *args, **kwargs):
        start = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            self.split[key] += time.perf_counter() - start


class Episode:
    """Runs one episode. ``env`` is a TabletopEnv; ``usage`` returns (calls, prompt, completion)
    token totals of the models in use so the episode can report its own share."""

    def __init__(
        self,
        learner: Learner,
        intention: Intention,
        user: User,
        executor: PlanExecutor,
        env: Any,
        config: EpisodeConfig | None = None,
        out_dir: str | Path | None = None,
        usage: Callable[[], tuple[int, int, int]] | None = None,
        on_round: Callable[[RoundLog], None] | None = None,
        extra_config: dict | None = None,
    ):
        self.learner, self.intention, self.user = learner, intention, user
        self.executor, self.env = executor, env
        self.config = config or EpisodeConfig()
        self.out = Path(out_dir) if out_dir else None
        self.usage = usage or (lambda: (0, 0, 0))
        self.on_round = on_round
        self.extra_config = extra_config or {}
        self.seeds = EpisodeSeeds.from_seed(self.config.seed)
        self.clock = _Clock()

    # -- helpers ---------------------------------------------------------------------------
    def _plan(self, goal: str, state: WorldState) -> tuple[list[Skill], str | None]:
        result = self.clock.timed("model_s", self.executor.to_plan, goal, state)
        failure = result.failure.feedback_text() if result.failure else None
        return list(result.plan), failure

    def _estimate_and_ground(self, scene: Scene, state: WorldState, final: bool) -> tuple[Estimate, list[list[Skill]], list[str | None]]:
        """z, y from the learner and y turned into plans; y that cannot be grounded is sent back
        to the learner ("I failed to generate the goal…") up to max_goal_retries times."""
        ask = self.learner.final if final else self.learner.estimate
        for attempt in range(self.config.max_goal_retries + 1):
            est = self.clock.timed("model_s", ask, scene, state)
            if est.plans is not None:
                return est, [list(p) for p in est.plans], [None] * len(est.plans)
            plans, failures = [], []
            for goal in est.goals:
                plan, failure = self._plan(goal, state)
                plans.append(plan)
                failures.append(failure)
            bad = [(g, f) for g, f in zip(est.goals, failures, strict=False) if f]
            if not bad or attempt == self.config.max_goal_retries:
                return est, plans, failures
            for goal, failure in bad:
                self.learner.execution_failed(goal, failure or "")
        raise AssertionError("unreachable")

    def _execute(self, scene: Scene, layout_seed: int, plan: list[Skill]) -> Trajectory:
        self.clock.timed("sim_s", self.env.reset, scene, layout_seed)
        return self.clock.timed("sim_s", self.env.execute, plan)

    def _video(self, traj: Trajectory, name: str) -> None:
        if self.out is not None and self.config.save_videos:
            from activeintent.sim.video import export_video

            self.clock.timed("render_s", export_video, traj, self.out / f"{name}.gif", fps=self.config.video_fps)

    def _test_scenes(self, shown: set[frozenset[str]]) -> list[Scene]:
        rng = np.random.default_rng(self.seeds.test)
        scenes: list[Scene] = []
        for _ in range(self.config.test_scenes):
            for _try in range(50):
                scene = self.intention.sample_scene(rng)
                if frozenset(scene.objects) not in shown:
                    break
            scenes.append(scene)
        return scenes

    # -- the loop --------------------------------------------------------------------------
    def run(self) -> EpisodeResult:
        start = time.perf_counter()
        calls0 = self.usage()
        cfg = self.config
        if self.out is not None:
            self.out.mkdir(parents=True, exist_ok=True)
            (self.out / "rounds.jsonl").write_text("")
        scene_rng = np.random.default_rng(self.seeds.scenes)
        layout_rng = np.random.default_rng(self.seeds.layouts)
        learner_rng = np.random.default_rng(self.seeds.learner)
        logs: list[RoundLog] = []
        shown: set[frozenset[str]] = set()
        signals = new_scenes = 0
        error = None
        after_new_scene = False
        # The test scenes are fixed up front (seeded) so per-round progress is measured on them.
        test_scenes = self._test_scenes(set())
        try:
            while signals < cfg.rounds:
                log = self._round(len(logs), scene_rng, layout_rng, learner_rng, test_scenes[0], after_new_scene)
                logs.append(log)
                shown.add(frozenset(log.scene))
                after_new_scene = bool(log.feedback.get("new_scene")) or log.feedback.get("choice") == "new_scene"
                new_scenes += after_new_scene
                # New-scene answers are free up to max_new_scenes; past that they use the budget.
                if not after_new_scene or new_scenes > cfg.max_new_scenes:
                    signals += 1
                log.signals_used = signals
                self._log_round(log)
                if log.done:
                    break
        except ModelError as err:
            error = f"model error in round {len(logs) + 1}: {err}"
        tests: list[TestLog] = []
        if error is None:
            test_scenes = [s if frozenset(s.objects) not in shown else None for s in test_scenes]
            fresh = iter(self._test_scenes(shown))
            try:
                for i, scene in enumerate(test_scenes):
                    tests.append(self._final_test(i, scene or next(fresh)))
            except ModelError as err:
                error = f"model error in the final test: {err}"
        calls1 = self.usage()
        success_rate = float(np.mean([t.success for t in tests])) if tests else 0.0
        result = EpisodeResult(
            method=self.learner.name,
            intention=self.intention.name,
            seed=cfg.seed,
            success=bool(tests) and all(t.success for t in tests),
            success_rate=success_rate,
            rounds_used=len(logs),
            signals_used=signals,
            final_preference=tests[0].preference if tests else "",
            final_goal=tests[0].goal if tests else "",
            retriever=self.learner.retriever,
            llm_calls=calls1[0] - calls0[0],
            prompt_tokens=calls1[1] - calls0[1],
            completion_tokens=calls1[2] - calls0[2],
            wall_s=round(time.perf_counter() - start, 3),
            time_split={k: round(v, 3) for k, v in self.clock.split.items()},
            per_round_success=[log.progress_success for log in logs if log.progress_success is not None],
            tests=tests,
            learner_stats=self.learner.stats(),
            error=error,
            config={"episode": cfg.model_dump(), **self.extra_config},
        )
        if self.out is not None:
            (self.out / "summary.json").write_text(result.model_dump_json(indent=2))
        return result

    def _round(self, index: int, scene_rng, layout_rng, learner_rng, test_scene: Scene, after_new_scene: bool) -> RoundLog:
        t0 = dict(self.clock.split)
        scene, source = None, "learner"
        if after_new_scene:
            source = "sampled (the user asked for a new scene)"
        else:
            scene = self.clock.timed("model_s", self.learner.design_scene, learner_rng)
            if scene is None:
                source = "sampled (the learner designs no scenes, or its choice was unusable)"
        if scene is None:
            # Two or three blocks and two bowls, bowls matching blocks' colours where possible:
            # such scenes can show most intentions, without knowing which one is hidden.
            scene = sample_scene(scene_rng, n_blocks=(2, 3), n_bowls=2, matching=True)
        layout_seed = int(layout_rng.integers(2**31))
        state = self.clock.timed("sim_s", self.env.reset, scene, layout_seed)
        est, plans, failures = self._estimate_and_ground(scene, state, final=False)
        trajectories = []
        for i, plan in enumerate(plans):
            traj = self._execute(scene, layout_seed, plan)
            trajectories.append(traj)
            failures[i] = failures[i] or ("; ".join(s.reason or "" for s in traj.failures) or None)
            self._video(traj, f"round{index + 1}_{'ab'[i] if len(plans) > 1 else 'y'}")
        h = self.user.respond(scene, trajectories)
        record = RoundRecord(index=index, scene=scene, estimate=est, plans=plans, failures=failures, feedback=h)
        r = self.clock.timed("model_s", self.learner.observe, record, trajectories)
        calls = self.learner.drain_transcript()
        progress = None
        if self.config.track_progress:
            progress = self._probe(test_scene)
            calls += [dict(c, probe=True) for c in self.learner.drain_transcript()]
        log = RoundLog(
            round=index + 1,
            scene=list(scene.objects),
            scene_source=source,
            layout_seed=layout_seed,
            preference=est.preference,
            goals=est.goals,
            plans=[describe_plan(p) for p in plans],
            failures=failures,
            feedback=h.model_dump(),
            retrieved=r,
            retriever=self.learner.retriever,
            done=est.done,
            progress_success=progress,
            calls=calls,
            timing={k: round(v - t0[k], 4) for k, v in self.clock.split.items()},
        )
        return log

    def _log_round(self, log: RoundLog) -> None:
        if self.out is not None:
            with (self.out / "rounds.jsonl").open("a") as f:
                f.write(log.model_dump_json() + "\n")
        if self.on_round:
            self.on_round(log)

    def _probe(self, scene: Scene) -> float:
        """Success of the current estimate on the first test scene, predicted symbolically."""
        from activeintent.world import layout

        state = WorldState(positions=layout(scene, self.seeds.test))
        try:
            est = self.clock.timed("model_s", self.learner.final, scene, state)
        except ModelError:
            return 0.0
        plan = est.plans[0] if est.plans else self._plan(est.goals[0], state)[0]
        states, _ = apply_plan(state, plan)
        return float(self.intention.satisfied(states[-1] if states else state))

    def _final_test(self, index: int, scene: Scene) -> TestLog:
        layout_seed = self.seeds.test + index
        state = self.clock.timed("sim_s", self.env.reset, scene, layout_seed)
        est, plans, failures = self._estimate_and_ground(scene, state, final=True)
        traj = self._execute(scene, layout_seed, plans[0])
        self._video(traj, f"final{index + 1}" if self.config.test_scenes > 1 else "final")
        final_state = traj.final_state or state
        return TestLog(
            calls=self.learner.drain_transcript(),
            scene=list(scene.objects),
            preference=est.preference,
            goal=est.goals[0],
            plan=describe_plan(plans[0]),
            failure=failures[0] or ("; ".join(s.reason or "" for s in traj.failures) or None),
            success=bool(self.intention.satisfied(final_state)),
            score=float(self.intention.score(final_state)),
        )


def read_rounds(path: str | Path) -> list[dict]:
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]
