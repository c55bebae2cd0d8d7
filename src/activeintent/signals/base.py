"""The Signal interface (APReL-style: a query type carries its response set and the one
observation model that both simulated users and Bayesian learners use, each with their own
parameters)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterator
from typing import ClassVar, Protocol

import numpy as np
from pydantic import BaseModel, ConfigDict

from activeintent.world.state import WorldState
from activeintent.world.trajectory import Trajectory


class Answer(BaseModel):
    """h: one answer of the user. ``new_scene`` = "this scene cannot show what I want"."""

    model_config = ConfigDict(extra="forbid")

    signal: str
    new_scene: bool = False

    def describe(self) -> str:
        """h in words, for prompts and logs (never more than the person gave)."""
        if self.new_scene:
            return "the user asked for a new scene: this one cannot show what they want"
        return self._describe()

    def _describe(self) -> str:
        return str(self.model_dump(exclude={"signal", "new_scene"}))

    @property
    def kind(self) -> str:
        """One word for h, the same in records, reports and exports: ``new_scene`` or the
        signal's own word (preference: A, B, cant_choose; stop: stop, no_stop)."""
        return "new_scene" if self.new_scene else self._kind()

    def _kind(self) -> str:
        return self.signal


class Judge(Protocol):
    """Judges outcomes under n intentions at once: n = 1 for a simulated user (its hidden
    intention), n = |H| for a Bayesian learner (its hypotheses)."""

    size: int

    def utility(self, state: WorldState) -> np.ndarray:
        """[n] u(s) = (score(s) + 1[satisfied(s)]) / 2 ∈ [0, 1]."""

    def first_away(self, traj: Trajectory) -> np.ndarray:
        """[n] index of the first step of τ that visibly moves away from the intention (-1: none)."""


class Signal(ABC):
    """One kind of sparse signal. ``model`` arguments are the signal's observation-model
    parameters (a pydantic model of class ``Model``): users and learners pass their own."""

    name: ClassVar[str]
    shows: ClassVar[int]  # trajectories per query (2 for A/B, 1 for stop)
    Answer: ClassVar[type[Answer]]
    Model: ClassVar[type[BaseModel]]
    page: ClassVar[str | None] = None  # the web app's page for this signal (None: no human UI)

    def new_scene(self) -> Answer:
        return self.Answer(signal=self.name, new_scene=True)

    def parse(self, payload: dict) -> Answer:
        """An answer from JSON (web app, logs); unknown fields are refused."""
        return self.Answer.model_validate({**payload, "signal": self.name})

    def learner_model(self) -> BaseModel:
        """What a learner assumes of people by default (not the simulated user's parameters)."""
        return self.Model()

    @abstractmethod
    def sample(self, shown: list[Trajectory], judge: Judge, model: BaseModel, rng: np.random.Generator) -> Answer:
        """A simulated user's answer to ``shown`` (``judge`` holds its one intention)."""

    @abstractmethod
    def likelihood(self, answer: Answer, shown: list[Trajectory], judge: Judge, model: BaseModel) -> np.ndarray:
        """[n] P(h | z) for each intention of ``judge`` (a density for continuous answers)."""

    @abstractmethod
    def predictive(self, shown: list[Trajectory], judge: Judge, model: BaseModel) -> np.ndarray:
        """[n, O] probabilities of O discretised answers, for expected information gain."""

    def predictive_many(self, queries: list[list[Trajectory]], judge: Judge, model: BaseModel
                        ) -> Iterator[np.ndarray]:
        """:meth:`predictive` of each query in turn (a signal may compute them together; the
        values must be the same)."""
        for shown in queries:
            yield self.predictive(shown, judge, model)
