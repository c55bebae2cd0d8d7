"""Scoring the learner's current answer on the test scenes (protocol.py): every test scene's
answer z, y is grounded, run in the symbolic world (and, for the final score in a physics env, on
the curve's scenes in physics), and judged by the hidden intention only after the learner has
answered; success is the share of feasible scenes satisfied. The episode decides when to score
(its loop); this module how."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from activeintent.envs import Env
from activeintent.intentions.base import Intention
from activeintent.learners.base import Estimate, Learner
from activeintent.records import TestLog
from activeintent.spec import ProtocolConfig
from activeintent.world import Scene, WorldState, apply_plan, describe_plan, layout
from activeintent.world.trajectory import Trajectory


class ScoredEpisode(Protocol):
    """What the scorer reads of an episode (``episode.Episode`` is one): scoring sits below the
    loop that calls it."""

    clock: Any
    env: Env
    intention: Intention
    learner: Learner
    protocol: ProtocolConfig
    show_final: str | None

    def emit(self, event: str, *args) -> None: ...

    def executor_calls(self) -> list[dict]: ...

    def ground(self, ask: Callable[[Scene, WorldState], Estimate], scene: Scene, state: WorldState) -> tuple: ...

    def video(self, traj: Trajectory, name: str, stop_time: float | None = None) -> None: ...


def first_feasible(intention: Intention, tests: list[tuple[Scene, int]]) -> int:
    """Index of the first test scene that can show ``intention`` (0 when none can)."""
    return next((i for i, (scene, _) in enumerate(tests) if intention.feasible(scene)), 0)


class Scorer:
    """Scores an episode's learner on its test scenes (uses the episode's learner, executor,
    env, intention, clock and observers)."""

    def __init__(self, episode: ScoredEpisode):
        self.episode = episode

    def score(self, k: int, tests: list[tuple[Scene, int]], final: bool) -> tuple[float | None, list[TestLog]]:
        """The learner's current answer on the test scenes (``final``: the whole pool, else the
        curve's); success over the feasible ones. Physics (a physics env, ``final`` only) runs on
        the curve's scenes."""
        ep = self.episode
        physics = final and ep.env.physical
        # The final attempt shown (final.gif, the web's final video) is on a scene that can show
        # the intention: the same scene final_z comes from (a web study may ask for the first).
        # Asking feasibility before the learner answers is safe: the learner never sees it.
        if not physics:
            shown = None
        else:
            shown = self.final_shown_index(tests) if ep.show_final else first_feasible(ep.intention, tests)
        logs = []
        for i, (scene, seed) in enumerate(tests if final else tests[:ep.protocol.test_scenes]):
            physics_here = physics and i < ep.protocol.test_scenes
            state = WorldState(positions=layout(scene, seed))
            est, plans, failures = ep.ground(ep.learner.final, scene, state)
            plan = plans[0] if plans else []
            states, _ = ep.clock.timed("scoring_s", apply_plan, state, plan)
            end = states[-1] if states else state
            feasible = bool(ep.intention.feasible(scene))  # only now, after the learner answered
            log = TestLog(scene=list(scene.objects), layout_seed=seed, z=est.z, goal=est.goals[0] if est.goals else "",
                          plan=describe_plan(plan), failure=failures[0] if failures else None, feasible=feasible,
                          success=bool(ep.clock.timed("scoring_s", ep.intention.satisfied, end)))
            if physics_here:
                ep.clock.timed("env_s", ep.env.reset, scene, seed)
                traj = ep.clock.timed("env_s", ep.env.execute, plan)
                log.success_physics = bool(ep.clock.timed("scoring_s", ep.intention.satisfied, traj.outcome))
                log.failure = log.failure or ("; ".join(s.reason or "" for s in traj.failures) or None)
                ep.emit("tested", k, i, scene, est, traj)
            if i == shown:
                if not physics_here:  # beyond the curve's scenes: run it for showing only, not scored
                    ep.clock.timed("env_s", ep.env.reset, scene, seed)
                    traj = ep.clock.timed("env_s", ep.env.execute, plan)
                if ep.protocol.video != "none":
                    ep.video(traj, "final")
                if ep.show_final:
                    ep.emit("final_shown", i, scene, est, traj, feasible)
            logs.append(log)
        ep.learner.drain_transcript()  # scoring calls are not part of any round's record
        ep.executor_calls()
        scored = [t.success for t in logs if t.feasible]
        rate = float(np.mean(scored)) if scored else None
        ep.emit("scored", k, rate)
        return rate, logs

    def final_shown_index(self, tests: list[tuple[Scene, int]]) -> int:
        ep = self.episode
        if ep.show_final == "first-feasible":
            return first_feasible(ep.intention, tests)
        if ep.show_final == "learner-showable":  # the learner's own P(shown), never the hidden rule
            mass = getattr(ep.learner, "shown_mass", None)
            if mass is not None:
                return next((i for i, (scene, _) in enumerate(tests) if mass(scene) >= 0.5), 0)
        return 0
