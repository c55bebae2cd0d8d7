"""The executor interface: instruction y → plan (a list of skills), the first half of τ = f(y).

Every executor first tries the deterministic parser (:mod:`activeintent.act.parse`) and only
calls its model when y is not in the canonical phrasing. Whatever goes wrong is returned as a
structured :class:`ExecutionFailure` (never raised), which the learner receives as feedback.
"""

from __future__ import annotations

import hashlib
from abc import ABC, abstractmethod
from functools import cache
from importlib.resources import files
from string import Template
from typing import Any, Literal

from pydantic import BaseModel, Field

from activeintent.llm.base import ChatModel
from activeintent.world.predict import apply_plan
from activeintent.world.skills import Skill, describe_skill
from activeintent.world.state import WorldState

Stage = Literal["parse", "plan", "program", "skill"]
EXECUTOR_NAMES = ("parse", "plan", "cap")


class ExecutionFailure(BaseModel):
    """Why y could not become (all of) τ: which stage failed, a one-line reason, details."""

    stage: Stage
    message: str
    details: dict[str, Any] = Field(default_factory=dict)

    def feedback_text(self) -> str:
        """What the learner is told (the original code's wording, plus the reason)."""
        return (
            "I failed to generate the goal; please generate a simpler goal similar to the "
            f"previous one. Reason ({self.stage}): {self.message}"
        )


class PlanResult(BaseModel):
    """The plan for y, the failure if any, and which executor produced it.

    A ``skill`` failure comes with the full plan: the steps that can be done still run.
    """

    plan: list[Skill] = Field(default_factory=list)
    failure: ExecutionFailure | None = None
    source: str
    program: str | None = None  # the model's program or JSON answer, for logs
    said: list[str] = Field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.failure is None


def check_plan(plan: list[Skill], state: WorldState) -> ExecutionFailure | None:
    """A ``skill`` failure listing every step the symbolic world model says cannot be done."""
    _, failures = apply_plan(state, plan)
    failed = [
        {"index": i, "skill": describe_skill(step), "reason": f.reason}
        for i, (step, f) in enumerate(zip(plan, failures, strict=True))
        if f is not None
    ]
    if not failed:
        return None
    first = failed[0]
    more = f" (and {len(failed) - 1} more failed steps)" if len(failed) > 1 else ""
    return ExecutionFailure(
        stage="skill",
        message=f"step {first['index'] + 1} '{first['skill']}' cannot be done: {first['reason']}{more}",
        details={"failed_steps": failed},
    )


@cache
def prompt_template(name: str) -> str:
    path = files("activeintent") / "prompts" / f"{name}.txt"
    return path.read_text()


def render_prompt(name: str, **values: object) -> tuple[str, str]:
    """(filled template ``name``, its version hash for the response cache)."""
    text = prompt_template(name)
    version = hashlib.sha256(text.encode()).hexdigest()[:12]
    return Template(text).substitute({k: str(v) for k, v in values.items()}).strip(), version


class Executor(ABC):
    """y → plan. Subclasses implement :meth:`_from_model` for instructions that do not parse."""

    name: str = "executor"

    def __init__(self, model: ChatModel | None = None) -> None:
        self.model = model

    def to_plan(self, instruction: str, state: WorldState) -> PlanResult:
        from activeintent.act.parse import ParseError, parse_instruction

        try:
            plan = parse_instruction(instruction, state.names)
        except ParseError as e:
            if e.kind != "syntax" or self.model is None:
                return PlanResult(source="parse", failure=e.failure())
            result = self._from_model(instruction, state)
        else:
            result = PlanResult(plan=plan, source="parse")
        if result.failure is None:
            result.failure = check_plan(result.plan, state)
        return result

    @abstractmethod
    def _from_model(self, instruction: str, state: WorldState) -> PlanResult:
        """The plan for an instruction the parser could not read (uses ``self.model``)."""


def make_executor(name: str, model: ChatModel | None = None, **options: Any) -> Executor:
    """The executor for ``--executor NAME`` (parse, plan or cap).

    Without a model, ``plan`` and ``cap`` read only the canonical phrasing (like ``parse``)
    and report anything else as a parse failure; methods that plan by themselves need no model.
    """
    key = name.strip().lower()
    if key == "parse":
        from activeintent.act.parse import ParseExecutor

        return ParseExecutor(model=None)
    if key == "plan":
        from activeintent.act.plan import PlanExecutor

        return PlanExecutor(model, **options)
    if key == "cap":
        from activeintent.act.cap import CapExecutor

        return CapExecutor(model, **options)
    raise ValueError(f"unknown executor {name!r}; valid executors: {', '.join(EXECUTOR_NAMES)}")
