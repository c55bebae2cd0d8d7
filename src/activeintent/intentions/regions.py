"""Intentions about where on the table blocks stand: corners, left half, warm left / cool right.

Table regions follow world.relations.table_position_name (a 3 × 3 grid of 20 cm cells);
halves split the table at x = 0 (left → right is −x → +x).

Where a block is wanted is the goal language's (activeintent.goals): Corners and InRegion's
halves, warm / cool by ColourClass; scenes and the placing of blocks are the protocol's.
"""

from __future__ import annotations

import numpy as np

from activeintent.goals.facts import facts
from activeintent.goals.relations import CORNER_CELL, InRegion
from activeintent.goals.selectors import ColourClass
from activeintent.goals.structures import Corners
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.placement import TABLE_INNER, free_spot, grid, nearest_first
from activeintent.world import (
    COLOR_NAMES,
    COOL_COLORS,
    WARM_COLORS,
    Relations,
    Scene,
    Skill,
    WorldState,
    relations,
)
from activeintent.world.skills import TABLE_POSITIONS

CORNERS = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")
# Blocks are put at least this far from the centre line so that settling cannot cross it.
HALF_MARGIN = 0.05


def _cell(corner: str) -> tuple[tuple[float, float], tuple[float, float]]:
    """The corner's 20 cm cell, kept 2 cm (half a block) inside the cell and table edges."""
    xs = (-0.28, -0.12) if "left" in corner else (0.12, 0.28)
    ys = (-0.38, -0.22) if corner.startswith("top") else (-0.78, -0.62)
    return xs, ys


def _scene(rng: np.random.Generator, n_blocks: int, n_bowls: int, block_colors: list[str] | None = None) -> Scene:
    blocks = block_colors or [str(c) for c in rng.choice(COLOR_NAMES, size=n_blocks, replace=False)]
    bowls = [str(c) for c in rng.choice(COLOR_NAMES, size=n_bowls, replace=False)]
    return Scene(objects=[f"{c} block" for c in blocks] + [f"{c} bowl" for c in bowls])


class BlocksInCorners(BlockwiseIntention):
    name = "blocks-in-corners"
    description = "Put each block on the table in a different corner of the table."

    corners = Corners()

    @classmethod
    def corner(cls, state: WorldState, block: str) -> str | None:
        """The corner cell (world.relations' name) ``block`` stands in on the table, if any."""
        return CORNER_CELL.get(cls.corners.corner(facts(state), block))

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        return self.corners.block_ok(f, f.blocks, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        # Corners already held by another block (wanted or not) are taken.
        taken = {self.corner(state, b) for b in state.blocks if b != block}
        here = state.pos(block)[:2]
        free = [c for c in CORNERS if c not in taken]
        for corner in nearest_first_named(free, here):

            def ok(after: WorldState, corner: str = corner) -> bool:
                return self.corner(after, block) == corner

            spots: list = [corner, *nearest_first(grid(*_cell(corner), step=0.035), np.array(TABLE_POSITIONS[corner]))]
            if step := free_spot(state, block, spots, accept=ok):
                return step
        return None

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.blocks) <= len(CORNERS)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        return _scene(rng, n_blocks, int(rng.integers(3 - n_blocks if n_blocks < 3 else 0, 3)))


def nearest_first_named(names: list[str], to: np.ndarray) -> list[str]:
    return sorted(names, key=lambda n: float(np.hypot(*(np.array(TABLE_POSITIONS[n]) - to))))


class _HalfIntention(BlockwiseIntention):
    """Blocks on the table, each in the half of the table chosen by ``side``."""

    region = InRegion()

    def side(self, block: str) -> str:
        raise NotImplementedError

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return self.region.ok(facts(state), block, f"{self.side(block)} half")

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        (x0, x1), ys = TABLE_INNER
        left = self.side(block) == "left"
        region = (x0, -HALF_MARGIN) if left else (HALF_MARGIN, x1)
        named = ["left side", "top left corner", "bottom left corner"] if left else [
            "right side", "top right corner", "bottom right corner"
        ]
        here = state.pos(block)[:2]
        spots = nearest_first_named(named, here) + nearest_first(grid(region, ys, step=0.04), here)

        def ok(after: WorldState) -> bool:
            return self.wanted(after, relations(after), block)

        return free_spot(state, block, spots, accept=ok)


class BlocksLeftHalf(_HalfIntention):
    name = "blocks-left-half"
    description = "Move all the blocks onto the left half of the table (on the table, not in bowls)."

    def side(self, block: str) -> str:
        return "left"

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        return _scene(rng, n_blocks, 1 + int(rng.integers(0, 2)))


class WarmLeftCoolRight(_HalfIntention):
    name = "warm-left-cool-right"
    description = (
        "Put warm-coloured blocks on the left half of the table and cool-coloured blocks on the "
        "right half."
    )

    classes = ColourClass()

    def is_warm(self, block: str) -> bool:
        return self.classes.pick(block, (), "warm")

    def side(self, block: str) -> str:
        return "left" if self.is_warm(block) else "right"

    def feasible(self, scene: Scene) -> bool:
        return any(self.is_warm(b) for b in scene.blocks) and any(not self.is_warm(b) for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        warm = [str(c) for c in rng.choice(sorted(WARM_COLORS), size=1 + int(rng.integers(0, 2)), replace=False)]
        cool = [str(c) for c in rng.choice(sorted(COOL_COLORS), size=1 + int(rng.integers(0, 2)), replace=False)]
        blocks = warm + cool
        rng.shuffle(blocks)
        n_bowls = int(rng.integers(max(0, 3 - len(blocks)), 6 - len(blocks)))
        return _scene(rng, len(blocks), n_bowls, block_colors=blocks)
