"""Intentions about blocks and bowls: colour match / mismatch (paper), one bowl, one block
per bowl, next to the same-colour bowl.

Where a block is wanted is the goal language's (activeintent.goals): InBowl, SeparateBowls,
OneBowl, OnTable and NextTo; scenes and the placing of blocks are the protocol's.
"""

from __future__ import annotations

import numpy as np

from activeintent.goals.facts import facts
from activeintent.goals.relations import InBowl, NextTo, OnTable
from activeintent.goals.structures import OneBowl as OneBowlNode
from activeintent.goals.structures import SeparateBowls
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.placement import free_spot
from activeintent.world import (
    COLOR_NAMES,
    PutIn,
    PutNextTo,
    Relations,
    Scene,
    Skill,
    WorldState,
    relations,
)
from activeintent.world.predict import apply_skill
from activeintent.world.scene import color_of, own_bowl


def _colors(rng: np.random.Generator, n: int, exclude: tuple[str, ...] | list[str] = ()) -> list[str]:
    pool = [c for c in COLOR_NAMES if c not in exclude]
    return [str(c) for c in rng.choice(pool, size=n, replace=False)]


def _blocks_in(rel: Relations, bowl: str) -> list[str]:
    return [a for a, w in rel.inside if w == bowl]


class ColorMatch(BlockwiseIntention):
    name = "color-match"
    description = "Put each block in the bowl of the same colour."

    in_bowl = InBowl()

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return self.in_bowl.ok(facts(state), block, "same")

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        return PutIn(block=block, bowl=own_bowl(block)) if own_bowl(block) in state.positions else None

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and all(own_bowl(b) in scene.bowls for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        colors = _colors(rng, 2 + int(rng.integers(0, 2)))  # 2 matching pairs (+ a distractor bowl)
        blocks, bowls = colors[:2], colors
        return Scene(objects=[f"{c} block" for c in blocks] + [f"{c} bowl" for c in bowls])


class ColorMismatch(BlockwiseIntention):
    name = "color-mismatch"
    description = "Put each block in a bowl of a different colour from the block."

    in_bowl = InBowl()

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return self.in_bowl.ok(facts(state), block, "other")

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        options = [w for w in state.bowls if color_of(w) != color_of(block)]
        if not options:
            return None
        # Spread blocks over the bowls; prefer a bowl whose colour matches some block (the
        # contrast with colour matching is then visible).
        block_colors = {color_of(b) for b in state.blocks}
        best = min(options, key=lambda w: (len(_blocks_in(rel, w)), color_of(w) not in block_colors))
        return PutIn(block=block, bowl=best)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and all(
            any(color_of(w) != color_of(b) for w in scene.bowls) for b in scene.blocks
        )

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        if rng.random() < 0.5:  # two blocks and the two bowls of their colours: swap them
            colors = _colors(rng, 2 + int(rng.integers(0, 2)))
            blocks, bowls = colors[:2], colors
        else:  # three blocks, bowls of two of their colours
            blocks = _colors(rng, 3)
            bowls = blocks[:2]
        return Scene(objects=[f"{c} block" for c in blocks] + [f"{c} bowl" for c in bowls])


class OneBowl(BlockwiseIntention):
    name = "one-bowl"
    description = "Put all the blocks together in one bowl (any bowl)."

    # Blocks go to the fullest bowl; starting a second bowl while another one already holds
    # blocks moves away (into_used).
    node = OneBowlNode(into_used=True)

    def target(self, state: WorldState) -> str | None:
        return self.node.fullest(facts(state), tuple(state.blocks))

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        target = self.target(state)
        return target is not None and facts(state).bowl_of[block] == target

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        target = self.target(state)
        return PutIn(block=block, bowl=target) if target else None

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        n_bowls = 1 + int(rng.integers(0, 2))
        colors = _colors(rng, n_blocks + n_bowls)
        return Scene(
            objects=[f"{c} block" for c in colors[:n_blocks]] + [f"{c} bowl" for c in colors[n_blocks:]]
        )


class OneBlockPerBowl(BlockwiseIntention):
    name = "one-block-per-bowl"
    description = "Put each block alone in its own bowl, whatever the colours."

    alone = SeparateBowls()

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        return self.alone.block_ok(f, f.blocks, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        empty = [w for w in state.bowls if not _blocks_in(rel, w)]
        if not empty:
            return None
        here = state.pos(block)[:2]
        best = min(empty, key=lambda w: float(np.hypot(*(state.pos(w)[:2] - here))))
        return PutIn(block=block, bowl=best)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and len(scene.bowls) >= len(scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_bowls = 2 + int(rng.integers(0, 2))
        blocks = _colors(rng, 2)
        bowls = _colors(rng, n_bowls)  # colours drawn independently: matches are a coincidence
        return Scene(objects=[f"{c} block" for c in blocks] + [f"{c} bowl" for c in bowls])


class NextToSameColorBowl(BlockwiseIntention):
    name = "next-to-same-color-bowl"
    description = "Put each block on the table next to (not in) the bowl of its own colour."

    on_table = OnTable()
    next_to = NextTo()

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        return self.on_table.ok(f, block, "") and self.next_to.ok(f, block, "own-bowl")

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        bowl = own_bowl(block)
        if bowl not in state.positions:
            return None

        def ok(after: WorldState) -> bool:
            return self.wanted(after, relations(after), block)

        step = PutNextTo(block=block, target=bowl, side="nearest")
        after, failure = apply_skill(state, step)
        if failure is None and ok(after):
            return step
        centre = state.pos(bowl)[:2]
        ring = [
            (float(centre[0] + r * np.cos(a)), float(centre[1] + r * np.sin(a)))
            for r in (0.1, 0.115)
            for a in np.linspace(0, 2 * np.pi, 24, endpoint=False)
        ]
        return free_spot(state, block, ring, accept=ok)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and all(own_bowl(b) in scene.bowls for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return ColorMatch().sample_scene(rng)
