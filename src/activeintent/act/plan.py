"""``--executor plan``: the model turns y into a JSON list of skills.

The answer schema is built per scene: its enum fields hold the scene's object names (blocks
where a block is needed, bowls where a bowl is), so with schema-constrained decoding the model
cannot name an object that is not on the table; the answer is validated again here anyway.
"""

from __future__ import annotations

from typing import Any, Literal, Union

from pydantic import BaseModel, Field, TypeAdapter, ValidationError, create_model

from activeintent.act.base import Executor, render_prompt
from activeintent.act.failures import ExecutionFailure, PlanResult
from activeintent.llm.base import ChatModel, Message, ModelError
from activeintent.memo import memoized
from activeintent.world.relations import describe_state
from activeintent.world.skills import TABLE_POSITIONS, Skill
from activeintent.world.state import WorldState

_SKILL = TypeAdapter(Skill)
SIDES = ("left", "right", "front", "behind", "nearest")


def _enum(values: tuple[str, ...]) -> Any:
    return Literal[values]  # type: ignore[valid-type]


def plan_schema(state: WorldState) -> type[BaseModel]:
    """The pydantic model of an answer ``{"steps": [...]}`` for this scene's objects."""
    return _schema(tuple(state.blocks), tuple(state.bowls), tuple(state.names))


@memoized(size=256, why="a scene's (blocks, bowls, objects): the answer model is a pure function of them")
def _schema(blocks: tuple[str, ...], bowls: tuple[str, ...], objects: tuple[str, ...]) -> type[BaseModel]:
    variants: list[type[BaseModel]] = []
    if not blocks:
        raise ValueError("the scene has no blocks, so no skill can be planned")
    block = (_enum(blocks), Field(description="the block to move"))
    if bowls:
        variants.append(create_model(
            "PutInStep", skill=(Literal["put_in"], ...), block=block,
            bowl=(_enum(bowls), Field(description="the bowl to put it in")),
        ))
    if len(blocks) > 1:
        variants.append(create_model(
            "PutOnStep", skill=(Literal["put_on"], ...), block=block,
            target=(_enum(blocks), Field(description="the block to put it on")),
        ))
    variants.append(create_model(
        "PutNextToStep", skill=(Literal["put_next_to"], ...), block=block,
        target=(_enum(objects), Field(description="the object to put it next to")),
        side=(_enum(SIDES), Field(description="which side; 'nearest' = the free side closest")),
    ))
    variants.append(create_model(
        "PutAtStep", skill=(Literal["put_at"], ...), block=block,
        position=(_enum(tuple(TABLE_POSITIONS)), Field(description="a named table position")),
    ))
    step_type: Any = Union[tuple(variants)]  # noqa: UP007 - built at run time
    return create_model("PlanAnswer", steps=(list[step_type], Field(description="the skills, in order")))


def answer_to_plan(answer: BaseModel, state: WorldState) -> list[Skill]:
    """Convert a validated answer into world skills (checking the names once more)."""
    plan = [_SKILL.validate_python(step.model_dump()) for step in answer.steps]  # type: ignore[attr-defined]
    for step in plan:
        for field in ("block", "bowl", "target"):
            name = getattr(step, field, None)
            if name is not None and name not in state.positions:
                raise ValueError(f"{name!r} is not on the table ({', '.join(state.names)})")
    return plan


class PlanExecutor(Executor):
    """y → structured plan with one schema-constrained model call."""

    name = "plan"

    def __init__(self, model: ChatModel | None = None, *, max_tokens: int = 400, parser_first: bool = False) -> None:
        super().__init__(model, parser_first=parser_first)
        self.max_tokens = max_tokens

    def messages(self, instruction: str, state: WorldState) -> tuple[list, str]:
        prompt, version = render_prompt(
            "executor_plan",
            objects=", ".join(state.names),
            state=describe_state(state),
            positions=", ".join(TABLE_POSITIONS),
            instruction=instruction.strip(),
        )
        return [Message(role="user", content=prompt)], version

    def _from_model(self, instruction: str, state: WorldState) -> PlanResult:
        assert self.model is not None
        try:
            schema = plan_schema(state)
        except ValueError as e:
            return PlanResult(source=self.name, failure=ExecutionFailure(stage="plan", message=str(e)))
        messages, version = self.messages(instruction, state)
        try:
            answer = self.model.structured(
                messages, schema, temperature=0.0, max_tokens=self.max_tokens, prompt_version=version
            )
        except ModelError as e:
            return PlanResult(
                source=self.name,
                failure=ExecutionFailure(stage="plan", message=f"the model gave no valid plan: {e}"),
            )
        if not isinstance(answer, BaseModel):
            return PlanResult(
                source=self.name,
                failure=ExecutionFailure(stage="plan", message="the model returned no structured answer"),
            )
        raw = answer.model_dump_json()
        try:
            plan = answer_to_plan(schema.model_validate(answer.model_dump()), state)
        except (ValidationError, ValueError) as e:
            return PlanResult(
                source=self.name, program=raw,
                failure=ExecutionFailure(
                    stage="plan", message=f"invalid plan: {str(e)[:300]}", details={"answer": answer.model_dump()}
                ),
            )
        if not plan:
            return PlanResult(
                source=self.name, program=raw,
                failure=ExecutionFailure(stage="plan", message="the plan is empty: no block would move"),
            )
        return PlanResult(plan=plan, source=self.name, program=raw)
