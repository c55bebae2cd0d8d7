"""What an executor returns for y: the plan (:class:`PlanResult`) or why y could not become
(all of) τ (:class:`ExecutionFailure`, never raised: the learner receives it as feedback)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, Field

from activeintent.world.predict import apply_plan
from activeintent.world.skills import Skill, describe_skill
from activeintent.world.state import WorldState

Stage = Literal["parse", "plan", "program", "skill"]


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
