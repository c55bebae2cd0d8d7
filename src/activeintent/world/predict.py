"""Symbolic world model: where a skill puts a block, without physics.

The simulator places blocks at exactly these targets, so the prediction of a plan's final
state matches the simulated one up to settling noise. Learners use it to score plans under
hypotheses cheaply; the real trajectory is still simulated for the user.
"""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel

from activeintent.world.relations import relations
from activeintent.world.scene import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_FLOOR,
    footprint_radius,
)
from activeintent.world.skills import TABLE_POSITIONS, PutAt, PutIn, PutNextTo, PutOn, Skill
from activeintent.world.state import WorldState

REACH_MARGIN = 0.02  # a target may lie this far outside the 60 cm square and still be reached
SIDE_GAP = 0.012  # clearance between a block placed "next to" something and that thing
SIDE_VECTORS = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "front": (0.0, -1.0), "behind": (0.0, 1.0)}


class SkillFailure(BaseModel):
    """A skill that cannot be done, with the reason (recorded, never raised)."""

    reason: str


def _objects_listing(state: WorldState) -> str:
    return ", ".join(state.names)


def _check_block(state: WorldState, name: str, role: str) -> SkillFailure | None:
    if name not in state.positions:
        return SkillFailure(reason=f"the {name} is not in the scene (objects: {_objects_listing(state)})")
    if state.kind(name) != "block":
        return SkillFailure(reason=f"the robot can only move blocks; the {role} {name} is a bowl")
    return None


def _free(state: WorldState, xy: np.ndarray, moving: str) -> str | None:
    """Name of an object whose footprint overlaps a block placed at xy, else None."""
    for other in state.names:
        if other == moving:
            continue
        if state.kind(other) == "block" and state.pos(other)[2] > BLOCK_SIZE:  # stacked: check its base
            continue
        dist = float(np.hypot(*(state.pos(other)[:2] - xy)))
        if dist < footprint_radius(other) + BLOCK_SIZE / 2 + 0.004:
            return other
    return None


def _in_reach(xy: np.ndarray) -> bool:
    (x0, x1), (y0, y1) = BOUNDS
    m = REACH_MARGIN
    return x0 - m <= xy[0] <= x1 + m and y0 - m <= xy[1] <= y1 + m


def target_position(state: WorldState, step: Skill) -> tuple[float, float, float] | SkillFailure:
    """Where ``step`` leaves its block (centre), or why it cannot be done."""
    if fail := _check_block(state, step.block, "object to move"):
        return fail
    rel = relations(state)
    if top := rel.above(step.block):
        return SkillFailure(reason=f"the {step.block} is under the {top}; move the {top} first")

    if isinstance(step, PutIn):
        if step.bowl not in state.positions:
            return SkillFailure(reason=f"the {step.bowl} is not in the scene (objects: {_objects_listing(state)})")
        if state.kind(step.bowl) != "bowl":
            return SkillFailure(reason=f"the {step.bowl} is not a bowl; use 'on' for blocks")
        already = [a for a, w in rel.inside if w == step.bowl and a != step.block]
        bowl = state.pos(step.bowl)
        z = BOWL_FLOOR + BLOCK_SIZE / 2 + BLOCK_SIZE * len(already)
        return (float(bowl[0]), float(bowl[1]), z)

    if isinstance(step, PutOn):
        if fail := _check_block(state, step.target, "target"):
            if step.target in state.positions:
                return SkillFailure(reason=f"the {step.target} is a bowl; use 'in' to put a block in a bowl")
            return fail
        if step.target == step.block:
            return SkillFailure(reason=f"cannot put the {step.block} on itself")
        if (top := rel.above(step.target)) and top != step.block:
            return SkillFailure(reason=f"the {step.target} already has the {top} on it")
        t = state.pos(step.target)
        return (float(t[0]), float(t[1]), float(t[2] + BLOCK_SIZE))

    if isinstance(step, PutNextTo):
        if step.target not in state.positions:
            return SkillFailure(reason=f"the {step.target} is not in the scene (objects: {_objects_listing(state)})")
        if step.target == step.block:
            return SkillFailure(reason=f"cannot put the {step.block} next to itself")
        t = state.pos(step.target)
        offset = footprint_radius(step.target) + BLOCK_SIZE / 2 + SIDE_GAP
        if step.side == "nearest":
            here = state.pos(step.block)[:2]
            sides = sorted(SIDE_VECTORS, key=lambda s: np.hypot(*(t[:2] + offset * np.array(SIDE_VECTORS[s]) - here)))
        else:
            sides = [step.side]
        reasons = []
        for side in sides:
            xy = t[:2] + offset * np.array(SIDE_VECTORS[side])
            if not _in_reach(xy):
                reasons.append(f"{side}: off the table")
                continue
            if blocker := _free(state, xy, step.block):
                reasons.append(f"{side}: the {blocker} is in the way")
                continue
            return (float(xy[0]), float(xy[1]), BLOCK_SIZE / 2)
        return SkillFailure(reason=f"no free place next to the {step.target} ({'; '.join(reasons)})")

    assert isinstance(step, PutAt)
    if isinstance(step.position, str):
        key = " ".join(step.position.lower().replace("the ", "").split())
        if key not in TABLE_POSITIONS:
            return SkillFailure(
                reason=f"unknown table position {step.position!r}; valid: {', '.join(TABLE_POSITIONS)}"
            )
        xy = np.array(TABLE_POSITIONS[key])
    else:
        xy = np.array(step.position, dtype=float)
    if not _in_reach(xy):
        return SkillFailure(reason=f"({xy[0]:.2f}, {xy[1]:.2f}) is out of reach (off the table)")
    if blocker := _free(state, xy, step.block):
        return SkillFailure(reason=f"the {blocker} is in the way at ({xy[0]:.2f}, {xy[1]:.2f})")
    return (float(xy[0]), float(xy[1]), BLOCK_SIZE / 2)


def apply_skill(state: WorldState, step: Skill) -> tuple[WorldState, SkillFailure | None]:
    """Predicted state after ``step`` (unchanged on failure) and the failure, if any."""
    target = target_position(state, step)
    if isinstance(target, SkillFailure):
        return state, target
    return state.moved(step.block, target), None


def apply_plan(state: WorldState, steps: list[Skill]) -> tuple[list[WorldState], list[SkillFailure | None]]:
    """States after each step (failed steps leave the state as it was) and per-step failures."""
    states, failures = [], []
    for step in steps:
        state, fail = apply_skill(state, step)
        states.append(state)
        failures.append(fail)
    return states, failures
