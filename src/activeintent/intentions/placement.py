"""Geometry shared by the intention library: towers, free spots, plan verification.

Plans are always checked against the symbolic world model (world.predict), so an intention
only returns a plan that the model says reaches a satisfying state.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np

from activeintent.world import (
    BOUNDS,
    WARM_COLORS,
    PutAt,
    Relations,
    Skill,
    WorldState,
    apply_plan,
    relations,
)
from activeintent.world.predict import SkillFailure, apply_skill, target_position
from activeintent.world.scene import color_of

if TYPE_CHECKING:
    from activeintent.intentions.base import Intention

# Spacing of blocks laid side by side with PutNextTo (block radius + block radius + 1.2 cm gap).
# Largest spread of the shared coordinate within a row or column (the "same y within ~2 cm").
LINE_TOL = 0.02


def towers(state: WorldState, rel: Relations) -> list[list[str]]:
    """Every block belongs to exactly one tower: a bottom-to-top chain of `on` relations.

    A lone block is a tower of height one. Bases may stand on the table or in a bowl.
    """
    result = []
    for base in state.blocks:
        if rel.below(base) is not None:
            continue
        chain, seen = [base], {base}
        while (top := rel.above(chain[-1])) is not None and top not in seen:
            chain.append(top)
            seen.add(top)
        result.append(chain)
    return sorted(result, key=len, reverse=True)


def standing_towers(state: WorldState, rel: Relations) -> list[list[str]]:
    """The towers whose base rests on the table, tallest first.

    Blocks put in a bowl one after another lie on each other (world.relations says `on`), but
    they are piled in the bowl, not stacked into a tower: a sentence about towers means these.
    """
    return [t for t in towers(state, rel) if on_table(rel, t[0])]


def on_table(rel: Relations, block: str) -> bool:
    """Resting directly on the table (not in a bowl, not on another block)."""
    return block in rel.on_table and rel.below(block) is None


def is_clear(rel: Relations, block: str) -> bool:
    return rel.above(block) is None


def top_first(state: WorldState, blocks: Iterable[str]) -> list[str]:
    """Blocks ordered so that a block above another one is moved first."""
    return sorted(blocks, key=lambda b: -state.pos(b)[2])


def is_warm(name: str) -> bool:
    return color_of(name) in WARM_COLORS


def grid(x_range: tuple[float, float], y_range: tuple[float, float], step: float = 0.03) -> list[tuple[float, float]]:
    xs = np.arange(x_range[0], x_range[1] + 1e-9, step)
    ys = np.arange(y_range[0], y_range[1] + 1e-9, step)
    return [(float(x), float(y)) for y in ys for x in xs]


TABLE_INNER = ((BOUNDS[0][0] + 0.03, BOUNDS[0][1] - 0.03), (BOUNDS[1][0] + 0.03, BOUNDS[1][1] - 0.03))


def free_spot(
    state: WorldState,
    block: str,
    candidates: Iterable[tuple[float, float] | str],
    accept=None,
) -> PutAt | None:
    """The first candidate (named position or xy) where the world model can put ``block``.

    ``accept(after_state)`` may reject spots that are free but not wanted.
    """
    for cand in candidates:
        step = PutAt(block=block, position=cand)
        after, fail = apply_skill(state, step)
        if fail is None and (accept is None or accept(after)):
            return step
    return None


def nearest_first(points: list[tuple[float, float]], to: np.ndarray) -> list[tuple[float, float]]:
    return sorted(points, key=lambda p: float(np.hypot(p[0] - to[0], p[1] - to[1])))


def run(state: WorldState, steps: list[Skill]) -> WorldState | None:
    """Predicted final state, or None if any step fails."""
    states, failures = apply_plan(state, steps)
    if any(f is not None for f in failures):
        return None
    return states[-1] if states else state


def verified(intention: Intention, state: WorldState, steps: list[Skill]) -> list[Skill] | None:
    """``steps`` if the world model says they satisfy ``intention`` from ``state``, else None."""
    final = run(state, steps)
    return steps if final is not None and intention.satisfied(final) else None


def park(state: WorldState, block: str) -> PutAt | None:
    """Put ``block`` on a free spot of the table near where it is (alone, not in a bowl)."""
    spots = nearest_first(grid(*TABLE_INNER, step=0.05), state.pos(block)[:2])
    return free_spot(state, block, spots, accept=lambda after: on_table(relations(after), block))


def can_do(state: WorldState, step: Skill) -> bool:
    return not isinstance(target_position(state, step), SkillFailure)
