"""What a learner is: it estimates z and y from the history of signals h (and r)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from activeintent.llm.base import ChatModel
from activeintent.signals import Answer
from activeintent.world import Scene, Skill, WorldState
from activeintent.world.trajectory import Trajectory


class Estimate(BaseModel):
    """z (the estimated intention, one sentence) and y (``goals``): one goal, or y^a and y^b
    when the signal shows two trajectories.

    A learner that has already grounded y in skills gives ``plans`` (one per goal) and the
    executor is skipped. ``done`` = the learner says it is confident (recorded; in the
    benchmark it does not end the episode). ``why`` explains the choice (e.g. EIG of the query
    and of the alternatives it beat; belief before the answer).
    """

    z: str
    goals: list[str]
    plans: list[list[Skill]] | None = None
    done: bool = False
    why: dict = Field(default_factory=dict)


class RoundRecord(BaseModel):
    """One feedback round: what was shown and what the user answered."""

    index: int
    scene: Scene
    estimate: Estimate
    plans: list[list[Skill]] = Field(default_factory=list)  # executed plans, one per goal
    failures: list[str | None] = Field(default_factory=list)  # per goal: why execution failed
    answer: Answer | None = None
    retrieved: str | None = None  # r (stop methods)


class Learner(ABC):
    """Base class of all methods. The episode loop calls, per round:
    ``design_scene`` → ``estimate`` → (execute, user answers h) → ``observe``;
    and ``final`` on each test scene, after every signal."""

    name: str = ""
    signal: str = "stop"  # the name of the signal plug-in it reads
    asks: bool = True  # False for the zero-signal baseline: it never shows a query
    may_finish: bool = False  # may its "done" end an episode outside the benchmark?
    retriever: str | None = None  # which retriever produced r (stop methods), for the logs
    # Does it design the scene that follows a "new scene" answer? (else the episode samples one)
    redesigns_after_new_scene: bool = False
    # Should the executor try its parser on y before its model? (the structured paper methods' y
    # are written for it)
    executor_parses_first: bool = False

    def execution_failed(self, goal: str, reason: str) -> None:  # noqa: B027 - optional hook
        """The executor could not turn goal y into motion; the next estimate should be simpler."""

    def showcases_alike(self, goals: list[str]) -> bool:
        """The two showcases y^a, y^b became the same motion on this table, so an answer would
        carry nothing. Return True when the learner was told and its next estimate may differ
        (the episode then asks again, within max_goal_retries); by default it is not asked."""
        return False

    def stats(self) -> dict:
        """Method-specific figures for the results."""
        return {}

    def diagnostics(self) -> dict:
        """Why it learned as it did, per answer (for the report's diagnostics section)."""
        return {}

    def drain_transcript(self) -> list[dict]:
        """Model calls and belief snapshots since the last drain, for rounds.jsonl."""
        return []

    def design_scene(self) -> Scene | None:
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
        """The current z and one y for a test scene (called after every signal)."""


class NoSettings(BaseModel):
    """The settings of a method that has none."""

    model_config = ConfigDict(extra="forbid")


@dataclass
class LearnerContext:
    """Everything a method may need to build its learner: the models, the learner's own random
    stream (EpisodeSeeds.learner, not the episode's seed) and its settings (an instance of its
    config class, ``Method.settings``)."""

    llm: ChatModel | None = None
    vlm: ChatModel | None = None
    learner_seed: int = 0
    settings: BaseModel = field(default_factory=NoSettings)


@dataclass
class Method:
    """A learner by name: what it reads, how it is built and the settings it takes.

    ``settings`` is its config class (pydantic): its fields are the method's settings, each
    declared there once; the command line offers them as options, the spec holds them
    (``learner.settings``) and the records keep them as the episode ran."""

    signal: str
    needs_llm: bool
    build: Callable[[LearnerContext], Learner]
    help: str = ""
    family: str = "ours"  # paper | ours | baseline
    goal_language: bool = False  # its hypotheses are goals of the language
    colour: str | None = None  # its colour in every report figure (None: a spare colour by a hash of its name)
    compared_with: str | None = None  # reports pair it with this method on the same trials (e.g. its random-question twin)
    settings: type[BaseModel] = NoSettings

    def own(self, given: dict[str, Any]) -> dict[str, Any]:
        """The given settings that are this method's (a benchmark gives one set to every method)."""
        return {k: v for k, v in given.items() if k in self.settings.model_fields}

    def configure(self, name: str, given: dict[str, Any]) -> BaseModel:
        """Its settings from the given values (the rest: the config class's defaults); ValueError
        naming the option when a value is bad or the method has no such setting."""
        unknown = sorted(set(given) - set(self.settings.model_fields))
        if unknown:
            valid = ", ".join(f"--{f.replace('_', '-')}" for f in self.settings.model_fields) or "none"
            raise ValueError(f"{', '.join('--' + u.replace('_', '-') for u in unknown)}: {name} has no such setting "
                             f"(its settings: {valid})")
        try:
            return self.settings.model_validate(given)
        except ValidationError as err:
            raise ValueError("; ".join(
                f"--{'.'.join(map(str, e['loc'])).replace('_', '-')}: {e['msg']} (got {e.get('input')!r})" if e["loc"]
                else e["msg"].removeprefix("Value error, ") for e in err.errors())) from None

    def __call__(self, ctx: LearnerContext) -> Learner:
        if self.needs_llm and ctx.llm is None:
            raise ValueError("this method needs a language model (--llm embedded, gguf:…, openai:…)")
        if not isinstance(ctx.settings, self.settings):
            ctx = LearnerContext(ctx.llm, ctx.vlm, ctx.learner_seed,
                                 self.settings.model_validate(ctx.settings.model_dump(exclude_unset=True)))
        return self.build(ctx)
