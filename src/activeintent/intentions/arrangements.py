"""Intentions that arrange blocks relative to each other: rows, columns, towers (paper: align,
stack), and warm blocks in bowls with cool blocks stacked.

Geometry matches world.predict: PutNextTo leaves neighbouring blocks ROW_PITCH = 5.2 cm apart
(centre to centre) at exactly the target's other coordinate, and world.relations calls two
blocks next to each other when the gap between their footprints is under 5 cm.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.placement import (
    LINE_TOL,
    ROW_PITCH,
    TABLE_INNER,
    grid,
    is_clear,
    is_warm,
    nearest_first,
    on_table,
    park,
    standing_towers,
    top_first,
    towers,
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

MIN_SPACING = 0.03  # two blocks on one surface closer than this would overlap


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
    """All blocks in one straight line on the table, neighbours next to each other.

    ``axis`` is the coordinate along the line (0: x, a left-right row; 1: y, a front-back
    column); the other coordinate may spread by at most LINE_TOL.
    """

    axis: int = 0
    sides: tuple[str, str] = ("right", "left")

    def line_ok(self, state: WorldState, rel: Relations, members: list[str] | tuple[str, ...]) -> bool:
        if not members or not all(on_table(rel, b) for b in members):
            return False
        across = [state.pos(b)[1 - self.axis] for b in members]
        if max(across) - min(across) > LINE_TOL:
            return False
        ordered = sorted(members, key=lambda b: state.pos(b)[self.axis])
        for a, b in zip(ordered, ordered[1:], strict=False):
            if state.pos(b)[self.axis] - state.pos(a)[self.axis] < MIN_SPACING or not rel.is_next_to(a, b):
                return False
        return True

    def longest_line(self, state: WorldState, rel: Relations) -> int:
        candidates = [b for b in state.blocks if on_table(rel, b)]
        for size in range(len(candidates), 1, -1):
            if any(self.line_ok(state, rel, combo) for combo in combinations(candidates, size)):
                return size
        return 1 if candidates else 0

    def satisfied(self, state: WorldState) -> bool:
        return self.line_ok(state, relations(state), state.blocks)

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        return self.longest_line(state, relations(state)) / n if n else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        rel = relations(after)
        block = step.block
        if block not in after.positions or block not in after.blocks:
            return False
        if not on_table(rel, block):  # stacked or in a bowl: never part of the line
            return True
        across = after.pos(block)[1 - self.axis]
        # Set beside blocks but in line with none of them (e.g. in front of a block when a
        # row is wanted). Touching a not-yet-moved block crosswise while joining the row is fine.
        neighbours = [
            other for other in after.blocks
            if other != block and on_table(rel, other) and rel.is_next_to(block, other)
        ]
        return bool(neighbours) and all(
            abs(after.pos(other)[1 - self.axis] - across) > LINE_TOL for other in neighbours
        )

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
    axis = 0
    sides = ("right", "left")


class AlignVertical(_LineIntention):
    name = "align-vertical"
    description = (
        "Align all the blocks vertically: one straight front-to-back column on the table, "
        "each block next to its neighbour, none stacked or in a bowl."
    )
    axis = 1
    sides = ("behind", "front")


class Stack(Intention):
    name = "stack"
    description = "Stack all the blocks into a single tower."

    # A tower stands on the table: blocks piled in a bowl are in the bowl, not a tower
    # (placement.standing_towers).

    def satisfied(self, state: WorldState) -> bool:
        ts = standing_towers(state, relations(state))
        return len(ts) == 1 and len(ts[0]) == len(state.blocks) > 0

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        return max((len(t) for t in standing_towers(state, relations(state))), default=0) / n if n else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        # Building a tower only ever puts blocks on blocks of a tower standing on the table;
        # anything else (the table, a bowl, a pile in a bowl) is a wasted move.
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        return rel.below(step.block) is None or not any(step.block in t for t in standing_towers(after, rel))

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

    # Towers stand on the table; blocks piled in a bowl are not a tower (see Stack).

    @staticmethod
    def heights(n: int) -> tuple[int, int]:
        return (n + 1) // 2, n // 2

    def satisfied(self, state: WorldState) -> bool:
        n = len(state.blocks)
        ts = standing_towers(state, relations(state))
        return n >= 2 and len(ts) == 2 and (len(ts[0]), len(ts[1])) == self.heights(n)

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if not n:
            return 0.0
        ts = standing_towers(state, relations(state))
        h1, h2 = self.heights(n)
        got = (min(len(ts[0]), h1) if ts else 0) + (min(len(ts[1]), h2) if len(ts) > 1 else 0)
        return got / n

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        if rel.below(step.block) is None:
            return True
        tower = next((t for t in standing_towers(after, rel) if step.block in t), None)
        return tower is None or len(tower) > self.heights(len(after.blocks))[0]

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

    @staticmethod
    def cool_tower(state: WorldState, rel: Relations) -> list[str]:
        """The longest run of cool blocks from the base of a tower standing on the table."""
        best: list[str] = []
        for tower in towers(state, rel):
            if not on_table(rel, tower[0]):
                continue
            run = []
            for b in tower:
                if is_warm(b):
                    break
                run.append(b)
            if len(run) > len(best):
                best = run
        return best

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        if is_warm(block):
            return rel.in_bowl(block) is not None
        return block in self.cool_tower(state, rel)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        if is_warm(block):
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
        warm = [b for b in scene.blocks if is_warm(b)]
        cool = [b for b in scene.blocks if not is_warm(b)]
        return bool(warm) and bool(cool) and bool(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        warm = [str(c) for c in rng.choice(sorted(WARM_COLORS), size=1 + int(rng.integers(0, 2)), replace=False)]
        cool = [str(c) for c in rng.choice(sorted(COOL_COLORS), size=2, replace=False)]
        blocks = warm + cool
        rng.shuffle(blocks)
        bowl = str(rng.choice(COLOR_NAMES))
        return Scene(objects=[f"{c} block" for c in blocks] + [f"{bowl} bowl"])
