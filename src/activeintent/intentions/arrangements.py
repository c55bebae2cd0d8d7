"""Intentions that arrange blocks relative to each other: rows, columns, towers (paper: align,
stack), and warm blocks in bowls with cool blocks stacked.

What a state must satisfy, its score and which moves go against it are the goal language's
(activeintent.goals): Row / Column, Tower, TwoTowers, InBowl and BottomOfTower over all the
blocks, with the options that say these intentions' own readings. Scenes and oracle plans are
the protocol's and stay here.

Geometry matches world.predict: PutNextTo leaves neighbouring blocks ROW_PITCH = 5.2 cm apart
(centre to centre) at exactly the target's other coordinate, and world.relations calls two
blocks next to each other when the gap between their footprints is under 5 cm.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from activeintent.goals.facts import Facts, facts
from activeintent.goals.relations import InBowl
from activeintent.goals.selectors import ColourClass
from activeintent.goals.structures import BottomOfTower, Column, Line, Row, Tower
from activeintent.goals.structures import TwoTowers as TwoTowersNode
from activeintent.intentions.base import Intention
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.placement import (
    TABLE_INNER,
    grid,
    is_clear,
    nearest_first,
    on_table,
    park,
    standing_towers,
    top_first,
    verified,
)
from activeintent.world import (
    COLOR_NAMES,
    COOL_COLORS,
    WARM_COLORS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Relations,
    Scene,
    Skill,
    WorldState,
    apply_skill,
    relations,
)
from activeintent.world.scene import ROW_PITCH


def _two_to_four_blocks(rng: np.random.Generator) -> Scene:
    """2–4 blocks and up to 2 bowls (3–5 objects): the scenes of the row and tower intentions."""
    n_blocks = 2 + int(rng.integers(0, 3))
    n_bowls = int(rng.integers(max(0, 3 - n_blocks), 6 - n_blocks))
    return _blocks_and_bowls(rng, n_blocks, min(n_bowls, 2))


def _blocks_and_bowls(rng: np.random.Generator, n_blocks: int, n_bowls: int) -> Scene:
    colors = [str(c) for c in rng.choice(COLOR_NAMES, size=n_blocks, replace=False)]
    bowls = [str(c) for c in rng.choice(COLOR_NAMES, size=n_bowls, replace=False)]
    return Scene(objects=[f"{c} block" for c in colors] + [f"{c} bowl" for c in bowls])


class _LineIntention(Intention):
    """All blocks in one straight line on the table, neighbours next to each other: the goal
    language's Row / Column over all the blocks (``node``), where a block of the line may carry
    another one (``loaded``)."""

    node: Line
    axis: int = 0  # the coordinate along the line, for the plans (0: x, 1: y)
    sides: tuple[str, str] = ("right", "left")

    def line_ok(self, state: WorldState, rel: Relations, members: list[str] | tuple[str, ...]) -> bool:
        return self.node.line(facts(state), tuple(members), "any")

    def satisfied(self, state: WorldState) -> bool:
        return self.node.holds(facts(state), tuple(state.blocks), "any")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "any") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.positions or step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "any")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _two_to_four_blocks(rng)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)
        centre = np.array([0.0, -0.5])
        anchors = sorted(
            (b for b in state.blocks if on_table(rel, b)),
            key=lambda b: float(np.hypot(*(state.pos(b)[:2] - centre))),
        )
        for anchor in anchors:
            others = top_first(state, [b for b in state.blocks if b != anchor])
            for side in self.sides:
                steps: list[Skill] = []
                prev = anchor
                for b in others:
                    steps.append(PutNextTo(block=b, target=prev, side=side))  # type: ignore[arg-type]
                    prev = b
                if found := verified(self, state, steps):
                    return found
        return self._plan_on_free_line(state)

    def _plan_on_free_line(self, state: WorldState) -> list[Skill] | None:
        """Fallback: put the blocks at explicit points of a line through free table space."""
        blocks = top_first(state, state.blocks)
        length = ROW_PITCH * (len(blocks) - 1)
        (x0, x1), (y0, y1) = TABLE_INNER
        along_range = (x0, x1 - length) if self.axis == 0 else (y0, y1 - length)
        across_range = (y0, y1) if self.axis == 0 else (x0, x1)
        if along_range[1] < along_range[0]:
            return None
        for start, across in nearest_first(grid(along_range, across_range, step=0.04), np.array([0.0, -0.5])):
            points = [(start + i * ROW_PITCH, across) for i in range(len(blocks))]
            if self.axis == 1:
                points = [(a, s) for s, a in points]
            steps: list[Skill] = [PutAt(block=b, position=p) for b, p in zip(blocks, points, strict=True)]
            if found := verified(self, state, steps):
                return found
        return None


class Align(_LineIntention):
    name = "align"
    description = (
        "Align all the blocks horizontally: one straight left-to-right row on the table, "
        "each block next to its neighbour, none stacked or in a bowl."
    )
    node = Row(loaded=True)
    axis = 0  # along x
    sides = ("right", "left")


class AlignVertical(_LineIntention):
    name = "align-vertical"
    description = (
        "Align all the blocks vertically: one straight front-to-back column on the table, "
        "each block next to its neighbour, none stacked or in a bowl."
    )
    node = Column(loaded=True)
    axis = 1  # along y
    sides = ("behind", "front")


class Stack(Intention):
    name = "stack"
    description = "Stack all the blocks into a single tower."

    # A tower stands on the table: blocks piled in a bowl are in the bowl, not a tower. Building
    # it only ever puts blocks on blocks of a standing tower; anything else (the table, a bowl, a
    # pile in a bowl) is a wasted move (onto_standing).
    node = Tower(onto_standing=True)

    def satisfied(self, state: WorldState) -> bool:
        return bool(state.blocks) and self.node.holds(facts(state), tuple(state.blocks), "any")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "any") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "any")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _two_to_four_blocks(rng)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)
        for keep in standing_towers(state, rel):
            if found := verified(self, state, _stack_onto(state, keep)):
                return found
        # No tower stands on the table (every block is in a bowl): set one block down first.
        for base in top_first(state, [b for b in state.blocks if is_clear(rel, b)]):
            if (step := park(state, base)) is None:
                continue
            after, _ = apply_skill(state, step)
            if found := verified(self, state, [step, *_stack_onto(after, [base])]):
                return found
        return None


def _stack_onto(state: WorldState, keep: list[str]) -> list[Skill]:
    """Put every block not in ``keep`` onto its top, topmost blocks first."""
    steps: list[Skill] = []
    top = keep[-1]
    for b in top_first(state, [b for b in state.blocks if b not in keep]):
        steps.append(PutOn(block=b, target=top))
        top = b
    return steps


class TwoTowers(Intention):
    name = "two-towers"
    description = "Stack the blocks into two towers of (nearly) equal height."

    # Towers stand on the table; blocks piled in a bowl are not a tower (see Stack). A move onto
    # a tower already as tall as the taller wanted one goes against it (onto_standing).
    node = TwoTowersNode(onto_standing=True)

    @staticmethod
    def heights(n: int) -> tuple[int, int]:
        return (n + 1) // 2, n // 2

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 2 and self.node.holds(facts(state), tuple(state.blocks), "")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 4

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _blocks_and_bowls(rng, 4, int(rng.integers(0, 2)))

    def plan(self, state: WorldState) -> list[Skill] | None:
        n = len(state.blocks)
        if n < 2:
            return None
        if self.satisfied(state):
            return []
        h1, h2 = self.heights(n)
        rel = relations(state)
        ts = standing_towers(state, rel)[:4]
        # Keep the bottoms of two standing towers, or of one (or none) and set bases down.
        keeps = [[ts[i], ts[j]] for i, j in combinations(range(len(ts)), 2)] + [[t] for t in ts] + [[]]
        for keep in keeps:
            kept = [t[:h] for t, h in zip(keep, (h1, h2), strict=False)]
            steps: list[Skill] = []
            current = state
            while len(kept) < 2:  # a new base: a clear block from a bowl or a tall tower
                taken = {b for t in kept for b in t}
                free = [b for b in top_first(current, current.blocks) if b not in taken and is_clear(relations(current), b)]
                step = next((s for b in free if (s := park(current, b)) is not None), None)
                if step is None:
                    break
                current, _ = apply_skill(current, step)
                steps.append(step)
                kept.append([step.block])
            if len(kept) < 2:
                continue
            tops = [kept[0][-1], kept[1][-1]]
            sizes = [len(kept[0]), len(kept[1])]
            taken = {b for t in kept for b in t}
            for b in top_first(current, [b for b in current.blocks if b not in taken]):
                k = 0 if sizes[0] < h1 else 1
                steps.append(PutOn(block=b, target=tops[k]))
                tops[k], sizes[k] = b, sizes[k] + 1
            if found := verified(self, state, steps):
                return found
        return None


class WarmInBowlsCoolStacked(BlockwiseIntention):
    name = "warm-in-bowls-cool-stacked"
    description = (
        "Put the warm-coloured blocks in bowls and stack the cool-coloured blocks into one "
        "tower on the table."
    )

    classes = ColourClass()
    in_bowl = InBowl()
    stacked = BottomOfTower()  # warm blocks put in bowls may stand on the cool tower

    @classmethod
    def cool_blocks(cls, f: Facts) -> tuple[str, ...]:
        return tuple(b for b in f.blocks if cls.classes.pick(b, f.bowls, "cool"))

    @classmethod
    def cool_tower(cls, state: WorldState, rel: Relations) -> list[str]:
        """The longest run of cool blocks from the base of a tower standing on the table."""
        f = facts(state)
        return cls.stacked.run(f, cls.cool_blocks(f))

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        if self.classes.pick(block, f.bowls, "warm"):
            return self.in_bowl.ok(f, block, "any")
        return block in self.stacked.run(f, self.cool_blocks(f))

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        if self.classes.pick(block, tuple(state.bowls), "warm"):
            if not state.bowls:
                return None
            here = state.pos(block)[:2]
            bowl = min(state.bowls, key=lambda w: float(np.hypot(*(state.pos(w)[:2] - here))))
            return PutIn(block=block, bowl=bowl)
        tower = self.cool_tower(state, rel)
        if not tower:
            return self.park(state, block)
        return PutOn(block=block, target=tower[-1])

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if self.classes.pick(b, tuple(scene.bowls), "warm")]
        cool = [b for b in scene.blocks if not self.classes.pick(b, tuple(scene.bowls), "warm")]
        return bool(warm) and bool(cool) and bool(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        warm = [str(c) for c in rng.choice(sorted(WARM_COLORS), size=1 + int(rng.integers(0, 2)), replace=False)]
        cool = [str(c) for c in rng.choice(sorted(COOL_COLORS), size=2, replace=False)]
        blocks = warm + cool
        rng.shuffle(blocks)
        bowl = str(rng.choice(COLOR_NAMES))
        return Scene(objects=[f"{c} block" for c in blocks] + [f"{bowl} bowl"])
