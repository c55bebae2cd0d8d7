"""Intentions that say, for each block on its own, where it is wanted (a bowl, a region, ...).

For these the score is the fraction of wanted blocks, and an executed step moves away from
the intention when it leaves the moved block somewhere unwanted or makes another block
unwanted (a drop in score).
"""

from __future__ import annotations

from abc import abstractmethod

from activeintent.intentions.base import Intention
from activeintent.intentions.placement import (
    TABLE_INNER,
    free_spot,
    grid,
    is_clear,
    nearest_first,
    on_table,
    top_first,
    verified,
)
from activeintent.world import Relations, Skill, WorldState, relations
from activeintent.world.predict import apply_skill


class BlockwiseIntention(Intention):
    """Base for intentions judged block by block."""

    @abstractmethod
    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        """Is ``block`` placed as the intention wants it?"""

    @abstractmethod
    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        """One skill that puts the (clear, unwanted) ``block`` where it is wanted."""

    def wanted_blocks(self, state: WorldState) -> list[str]:
        rel = relations(state)
        return [b for b in state.blocks if self.wanted(state, rel, b)]

    def score(self, state: WorldState) -> float:
        blocks = state.blocks
        return len(self.wanted_blocks(state)) / len(blocks) if blocks else 0.0

    def satisfied(self, state: WorldState) -> bool:
        return bool(state.blocks) and len(self.wanted_blocks(state)) == len(state.blocks)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.positions:
            return False
        return not self.wanted(after, relations(after), step.block)

    def park(self, state: WorldState, block: str) -> Skill | None:
        """Put ``block`` somewhere free on the table (to uncover the block below it)."""
        spots = nearest_first(grid(*TABLE_INNER, step=0.05), state.pos(block))
        return free_spot(state, block, spots, accept=lambda s: on_table(relations(s), block))

    def plan(self, state: WorldState) -> list[Skill] | None:
        steps: list[Skill] = []
        current = state
        for _ in range(4 * len(state.blocks) + 4):
            rel = relations(current)
            unwanted = [b for b in current.blocks if not self.wanted(current, rel, b)]
            if not unwanted:
                return verified(self, state, steps)
            clear = [b for b in top_first(current, unwanted) if is_clear(rel, b)]
            if clear:
                step = self.place(current, rel, clear[0])
            else:  # every unwanted block is under a wanted one: lift the top of that stack
                top = unwanted[0]
                while (up := rel.above(top)) is not None:
                    top = up
                step = self.park(current, top)
            if step is None:
                return None
            current, failure = apply_skill(current, step)
            if failure is not None:
                return None
            steps.append(step)
        return None
