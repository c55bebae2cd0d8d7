"""Simulated users with a hidden intention: they give the sparse signal h for what they see.

A :class:`SimulatedUser` holds one intention and a :class:`UserProfile`; it answers any
registered signal through that signal's own observation model (``activeintent.signals``),
with the user's parameters — never the learner's. It first decides whether the scene can
show its intention at all (the "new scene" answer, with the profile's error rates), then
samples the signal's answer. All randomness comes from the user's own generator.

Presets (``--user``): ``exact`` (no noise; for debugging), ``paper`` (mild noise), ``human``
(the default for published numbers; see :data:`PRESETS` for each figure and its source).
Users never import learners, and learners never import users.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from activeintent.intentions.base import Intention
from activeintent.memo import BoundedCache
from activeintent.registry import Registry
from activeintent.signals import Answer, Signal, get_signal
from activeintent.world import Scene, WorldState
from activeintent.world.trajectory import StepRecord, Trajectory


class IntentionJudge:
    """The :class:`activeintent.signals.Judge` of one hidden intention (n = 1)."""

    size = 1

    def __init__(self, intention: Intention):
        self.intention = intention
        self._away: BoundedCache[tuple, bool] = BoundedCache(1024)  # by the step (states, skill, ok)

    def utility(self, state: WorldState) -> np.ndarray:
        score = float(np.clip(self.intention.score(state), 0.0, 1.0))
        return np.array([0.5 * (score + float(self.intention.satisfied(state)))])

    def moves_away(self, step: StepRecord) -> bool:
        """A step moves away when the intention says so; a failed step only when it visibly
        made things worse (the score dropped, e.g. it knocked a tower over)."""
        key = (tuple(sorted(step.state_before.positions.items())), tuple(sorted(step.state_after.positions.items())),
               step.skill.model_dump_json(), step.ok)
        return self._away.get_or_make(key, lambda: bool(
            self.intention.step_moves_away(step.state_before, step.state_after, step.skill) if step.ok
            else self.intention.score(step.state_after) < self.intention.score(step.state_before) - 1e-9))

    def first_away(self, traj: Trajectory) -> np.ndarray:
        for step in traj.steps:
            if self.moves_away(step):
                return np.array([step.index])
        return np.array([-1])


class UserProfile(BaseModel):
    """Every parameter of a simulated user (logged with each result, never shown to learners)."""

    model_config = ConfigDict(extra="forbid", ser_json_inf_nan="constants")

    name: str = "custom"
    models: dict[str, dict[str, Any]] = Field(
        default_factory=dict, description="per signal: parameters of its observation model")
    beta_range: tuple[float, float] | None = Field(
        None, description="draw the preference rationality β per user, uniformly in this range")
    new_scene_false: float = Field(0.0, ge=0, le=1, description="P(asks for a new scene although the scene could show the intention)")
    new_scene_miss: float = Field(0.0, ge=0, le=1, description="P(answers normally although the scene cannot show the intention)")

    def model_for(self, signal: Signal, rng: np.random.Generator) -> BaseModel:
        params = dict(self.models.get(signal.name, {}))
        if self.beta_range is not None and "beta" in signal.Model.model_fields:
            params["beta"] = float(rng.uniform(*self.beta_range))
        return signal.Model(**params)


USER_PRESETS: Registry[UserProfile] = Registry("user preset")

USER_PRESETS.register("exact", lambda: UserProfile(
    name="exact",
    models={"preference": {"beta": float("inf"), "lapse": 0.0},
            "stop": {"delay_mean": 0.5, "delay_sd": 0.15, "late_tail": 0.0, "false_stop": 0.0,
                     "missed_stop": 0.0, "lapse": 0.0}},
), help="no noise at all (debugging only: it is the learner's best case)")

USER_PRESETS.register("paper", lambda: UserProfile(
    name="paper",
    models={"preference": {"beta": 20.0, "lapse": 0.0},
            "stop": {"delay_mean": 0.5, "delay_sd": 0.15, "late_tail": 0.0, "false_stop": 0.05,
                     "missed_stop": 0.05, "lapse": 0.0}},
    new_scene_false=0.02, new_scene_miss=0.05,
), help="mild noise: β = 20, 5 % false and missed stops")

# `human`: figures from what is known of people, deliberately unlike any learner's assumption.
# - Preference rationality: Boltzmann β drawn per user in [2, 5] (on utilities in [0, 1]),
#   i.e. a user picks the better of two outcomes that differ by half the scale 73–92 % of the time;
#   indifference margin 0.1, 5 % lapses.
# - Stop: choice reaction times to visual events are right-skewed, median ≈ 0.6 s with a long
#   tail, modelled log-normal (mean 0.7 s, sd 0.35 s); a wrong move is only recognised once
#   the block has travelled 30 % of the way after lifting; 10 % of stops come late (anywhere
#   after the bad step starts), 5 % false stops, 10 % missed bad moves, 2 % lapses.
# - "New scene": asked 5 % of the time without reason; 20 % of unusable scenes go unnoticed.
USER_PRESETS.register("human", lambda: UserProfile(
    name="human",
    beta_range=(2.0, 5.0),
    models={"preference": {"indifference": 0.1, "confusion": 1.0, "lapse": 0.05},
            "stop": {"delay": "lognormal", "delay_mean": 0.7, "delay_sd": 0.35, "visible_after": 0.3,
                     "late_tail": 0.1, "false_stop": 0.05, "missed_stop": 0.1, "lapse": 0.02}},
    new_scene_false=0.05, new_scene_miss=0.2,
), help="noisy like people (default for published numbers)")


def user_profile(preset: str) -> UserProfile:
    return USER_PRESETS.make(preset)


class SimulatedUser:
    """A user holding ``intention`` who answers queries of ``signal``."""

    def __init__(self, intention: Intention, signal: Signal | str, profile: UserProfile | None = None,
                 rng: np.random.Generator | int = 0):
        self.intention = intention
        self.signal = get_signal(signal) if isinstance(signal, str) else signal
        self.profile = profile or user_profile("exact")
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        self.model = self.profile.model_for(self.signal, self.rng)
        self.judge = IntentionJudge(intention)

    def parameters(self) -> dict:
        """What this user actually is (β drawn, etc.), for the results; learners never see it."""
        return {"profile": self.profile.model_dump(mode="json"), "signal_model": self.model.model_dump(mode="json")}

    def respond(self, scene: Scene, trajectories: list[Trajectory]) -> Answer:
        """h for the trajectories shown in ``scene``."""
        u = self.rng.random()  # one draw per answer for the new-scene decision
        if self.intention.feasible(scene):
            if u < self.profile.new_scene_false:
                return self.signal.new_scene()
        elif u >= self.profile.new_scene_miss:
            return self.signal.new_scene()
        return self.signal.sample(trajectories, self.judge, self.model, self.rng)
