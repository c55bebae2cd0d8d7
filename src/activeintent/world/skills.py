"""The robot's skills (the paper's three, plus Code-as-Policies table positions).

A plan is a list of skills; each moves one block. Bowls never move.
Sides: left/right along x, front/behind along y (behind = towards the top side).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, Field

Side = Literal["left", "right", "front", "behind", "nearest"]
SIDES = ("left", "right", "front", "behind")  # the sides of an object PutNextTo names (besides "nearest")

# Named table positions (Code-as-Policies): corners, sides and the middle.
TABLE_POSITIONS: dict[str, tuple[float, float]] = {
    "top left corner": (-0.25, -0.25),
    "top side": (0.0, -0.25),
    "top right corner": (0.25, -0.25),
    "left side": (-0.25, -0.5),
    "middle": (0.0, -0.5),
    "right side": (0.25, -0.5),
    "bottom left corner": (-0.25, -0.75),
    "bottom side": (0.0, -0.75),
    "bottom right corner": (0.25, -0.75),
}


class PutIn(BaseModel):
    """Pick a block and place it in a bowl."""

    skill: Literal["put_in"] = "put_in"
    block: str
    bowl: str


class PutOn(BaseModel):
    """Pick a block and place it on another block."""

    skill: Literal["put_on"] = "put_on"
    block: str
    target: str


class PutNextTo(BaseModel):
    """Pick a block and place it next to an object (a side, or the free side nearest)."""

    skill: Literal["put_next_to"] = "put_next_to"
    block: str
    target: str
    side: Side = "nearest"


class PutAt(BaseModel):
    """Pick a block and place it at a named table position or an (x, y) point."""

    skill: Literal["put_at"] = "put_at"
    block: str
    position: str | tuple[float, float]


Skill = Annotated[PutIn | PutOn | PutNextTo | PutAt, Field(discriminator="skill")]


def skill_key(step: Skill) -> tuple:
    """A hashable identity of a step: equal exactly when the reprs are (a point's coordinates
    compared by repr, so that 0.0 and -0.0 stay apart), at a fraction of pydantic's repr."""
    return (step.skill, *(repr(v) if isinstance(v, tuple) else v for v in step.__dict__.values()))


class Plan(BaseModel):
    steps: list[Skill] = Field(default_factory=list)


def describe_skill(step: Skill) -> str:
    """Canonical phrasing, as the `parse` executor reads it back."""
    if isinstance(step, PutIn):
        return f"put the {step.block} in the {step.bowl}"
    if isinstance(step, PutOn):
        return f"put the {step.block} on the {step.target}"
    if isinstance(step, PutNextTo):
        if step.side == "nearest":
            return f"put the {step.block} next to the {step.target}"
        where = {"left": "left of", "right": "right of", "front": "in front of", "behind": "behind"}[
            step.side
        ]
        return f"put the {step.block} {where} the {step.target}"
    pos = step.position
    if isinstance(pos, str):
        return f"put the {step.block} at the {pos}"
    return f"put the {step.block} at ({pos[0]:.2f}, {pos[1]:.2f})"


def describe_plan(steps: list[Skill]) -> str:
    return ", then ".join(describe_skill(s) for s in steps) if steps else "do nothing"
