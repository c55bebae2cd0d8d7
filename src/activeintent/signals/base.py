"""The Signal interface (APReL-style: a query type carries its response set and the one
observation model that both simulated users and Bayesian learners use, each with their own
parameters)."""

from __future__ import annotations

import sys
from abc import ABC, abstractmethod
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar, Protocol

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

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


class AnswerRejected(ValueError):
    """An answer that cannot be taken: ``status`` is the HTTP-like code a server gives (404
    nothing asked, 409 wrong round or state, 422 malformed); ``code`` a stable word for it."""

    def __init__(self, message: str, status: int = 409, code: str | None = None):
        super().__init__(message)
        self.status = status
        self.code = code


MAX_ROUND = 10_000


class WebForm(BaseModel):
    """What a signal's web page posts as one answer: the signal (``kind``), the round it answers
    and the browser's clock, plus the signal's own fields (a subclass). Unknown fields are
    refused and types are strict: true is not 1, "1" is not 1 (pydantic would convert each)."""

    model_config = ConfigDict(extra="forbid", strict=True)
    # form fields kept in the server's log beside the answer (what the page did, not h)
    logged: ClassVar[tuple[str, ...]] = ("client_ts",)

    kind: str
    round: int = Field(ge=1, le=MAX_ROUND, description="the round this answers (as given in the session state)")
    client_ts: float | None = Field(None, ge=0, le=1e11, allow_inf_nan=False,
                                    description="browser clock (s since the epoch)")


@dataclass
class ShownRound:
    """What the person was shown in one round of the web app, for turning a page's form into h:
    the trajectories τ, the media length of each one's video (seconds), the videos' frame rate,
    and how the video was watched (``ready``/``ended`` times, ``replays``)."""

    trajectories: list[Trajectory]
    video_lengths: list[float]
    fps: int
    viewing: dict = field(default_factory=lambda: {"ready": None, "ended": None, "replays": 0})


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
    # The human side (None: no web page; simulated users only). Files live in ``page_folder``
    # of the folder of the module that defines the signal: ``page`` is the answer page's HTML
    # (served at /signal/<name>), ``how`` an HTML fragment the start page shows, ``page_assets``
    # the further files the page loads (at /signal/<name>/<file>); ``WebForm`` is what the page
    # posts, read by :meth:`from_web`; ``buttons`` the answer buttons whose order is
    # counterbalanced across participants.
    page_folder: ClassVar[str] = "."
    page: ClassVar[str | None] = None
    how: ClassVar[str | None] = None
    page_assets: ClassVar[tuple[str, ...]] = ()
    WebForm: ClassVar[type[WebForm] | None] = None
    buttons: ClassVar[tuple[str, ...]] = ()

    def new_scene(self) -> Answer:
        return self.Answer(signal=self.name, new_scene=True)

    def parse(self, payload: dict) -> Answer:
        """An answer from JSON (web app, logs); unknown fields are refused."""
        return self.Answer.model_validate({**payload, "signal": self.name})

    @classmethod
    def page_dir(cls) -> Path:
        """Where the signal's page files are: the folder of the module that defines it."""
        module = sys.modules.get(cls.__module__)
        where = getattr(module, "__file__", None)
        if where is None:
            raise RuntimeError(f"signal {cls.name!r}: module {cls.__module__} has no file to find its page next to")
        return (Path(where).resolve().parent / cls.page_folder).resolve()

    @classmethod
    def page_file(cls, name: str) -> Path:
        """One of the signal's page files (``page``, ``how`` or one of ``page_assets``)."""
        if name is None or name not in {cls.page, cls.how, *cls.page_assets}:
            raise KeyError(f"signal {cls.name!r} has no page file {name!r}")
        return cls.page_dir() / name

    def button_order(self, slot: int, counterbalance: bool = True) -> list[str]:
        """The answer buttons for participant ``slot``: the cyclic shifts of ``buttons`` put every
        answer once in every position (a Latin square)."""
        b = list(self.buttons)
        k = slot % len(b) if b and counterbalance else 0
        return b[k:] + b[:k]

    def from_web(self, form: WebForm, shown: ShownRound) -> Answer:
        """h from what the page posted (``form``, of class ``WebForm``) about what was ``shown``;
        raises :class:`AnswerRejected` for an answer that cannot be one."""
        raise NotImplementedError(f"signal {self.name!r} has no web page")

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
