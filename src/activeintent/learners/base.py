"""What a learner is: it estimates z and y from the history of signals h (and r)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Literal

import numpy as np
from pydantic import BaseModel, Field

from activeintent.signals import PreferenceFeedback, StopFeedback
from activeintent.sim.trajectory import Trajectory
from activeintent.world import Scene, Skill, WorldState


class Estimate(BaseModel):
    """z (``preference``) and y (``goals``): one goal, or y^a and y^b for the preference method.

    A learner that has already grounded y in skills gives ``plans`` (one per goal) and the
    executor is skipped. ``done`` = the learner is confident and needs no more signals.
    """

    preference: str
    goals: list[str]
    plans: list[list[Skill]] | None = None
    done: bool = False


class RoundRecord(BaseModel):
    """One feedback round: what was shown and what the user said."""

    index: int
    scene: Scene
    estimate: Estimate
    plans: list[list[Skill]] = Field(default_factory=list)  # executed plans, one per goal
    failures: list[str | None] = Field(default_factory=list)  # per goal: why execution failed
    feedback: PreferenceFeedback | StopFeedback | None = None
    retrieved: str | None = None  # r (stop methods)


class Learner(ABC):
    """Base class of all methods. The episode loop calls, per round:
    ``design_scene`` → ``estimate`` → (execute, user answers h) → ``observe``;
    and at the end ``final`` on a fresh scene."""

    name: str = ""
    signal: Literal["preference", "stop"] = "stop"
    retriever: str | None = None  # which retriever produced r (stop methods), for the logs

    def execution_failed(self, goal: str, reason: str) -> None:  # noqa: B027 - optional hook
        """The executor could not turn goal y into motion; the next estimate should be simpler."""

    def stats(self) -> dict:
        """Method-specific figures for the results (e.g. bits gained per signal)."""
        return {}

    def drain_transcript(self) -> list[dict]:
        """Model calls made since the last drain (prompt, answer, timing), for rounds.jsonl."""
        return []

    def design_scene(self, rng: np.random.Generator) -> Scene | None:
        """Choose the next scene (3–5 objects), or None to let the episode sample one."""
        return None

    @abstractmethod
    def estimate(self, scene: Scene, state: WorldState) -> Estimate:
        """z_{i+1}, y_{i+1} for this scene: eq. (1)(2) or (5)(6)."""

    @abstractmethod
    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        """Take the user's signal h for the round; return r when a retriever ran (eq. 3–4)."""

    @abstractmethod
    def final(self, scene: Scene, state: WorldState) -> Estimate:
        """The final z and one y for a fresh test scene."""
