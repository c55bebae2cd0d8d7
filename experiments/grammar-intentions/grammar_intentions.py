"""Four hidden intentions that the Bayesian learners' grammar can express but that are not
among the built-in ones, for checking that the learners generalise beyond the benchmark:

- PINK_BOWL: every block goes in the pink bowl;
- NEXT_TO_YELLOW: every other block goes on the table right next to the yellow block;
- LEFT_SIDE: every block goes on the table in the left-side cell (middle of the left edge);
- WARM_LEFT_COOL_RIGHT: warm-coloured blocks on the left half, cool-coloured on the right.

They are plain Intention subclasses written with the world model only (nothing is taken from
the learners). Run the Bayesian learners on them, next to the paper's four:

    bin/activeintent bench --methods bayes-preference,bayes-stop --suite paper --llm none \\
        --intention-file experiments/grammar-intentions/grammar_intentions.py:PINK_BOWL \\
        --intention-file experiments/grammar-intentions/grammar_intentions.py:NEXT_TO_YELLOW \\
        --intention-file experiments/grammar-intentions/grammar_intentions.py:LEFT_SIDE \\
        --intention-file experiments/grammar-intentions/grammar_intentions.py:WARM_LEFT_COOL_RIGHT --out runs/grammar
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_RADIUS,
    WARM_COLORS,
    PutAt,
    PutIn,
    PutNextTo,
    Relations,
    Scene,
    Skill,
    WorldState,
    apply_plan,
    apply_skill,
    relations,
    sample_scene,
    table_position_name,
)

ROOM = 0.01  # spots the robot picks itself keep a finger's width from other objects


def _is_warm(block: str) -> bool:
    return WorldState.color(block) in WARM_COLORS


def _flat(rel: Relations, block: str) -> bool:
    """On the table itself: not in a bowl, not on a block, nothing on top."""
    return block in rel.on_table and rel.below(block) is None and rel.above(block) is None


def _on_table(rel: Relations, block: str) -> bool:
    return block in rel.on_table and rel.below(block) is None


def _roomy(state: WorldState, block: str) -> bool:
    here = state.pos(block)
    for other in state.names:
        if other == block:
            continue
        if state.kind(other) == "bowl":
            need = BOWL_RADIUS + BLOCK_SIZE / 2 + ROOM
        elif abs(state.pos(other)[2] - here[2]) < BLOCK_SIZE / 2:
            need = BLOCK_SIZE + ROOM
        else:
            continue
        if np.hypot(*(state.pos(other)[:2] - here[:2])) < need:
            return False
    return True


def _grid(xs: tuple[float, float], ys: tuple[float, float], step: float = 0.02) -> list[tuple[float, float]]:
    return [(float(x), float(y)) for x in np.arange(xs[0], xs[1] + 1e-9, step)
            for y in np.arange(ys[0], ys[1] + 1e-9, step)]


def _nearest(points: list[tuple[float, float]], to) -> list[tuple[float, float]]:
    return sorted(points, key=lambda p: float(np.hypot(p[0] - to[0], p[1] - to[1])))


class _PerBlockRule(Intention):
    """A rule that says, for each block of a group, where it should be.

    Subclasses give the group, ``ok`` (is this block where the rule wants it?) and ``moves``
    (candidate skills that put it there, tried in order; ``variant`` changes the order, for
    rules whose first greedy choice can leave no room for the last blocks).
    """

    variants = 1

    def group(self, blocks: list[str]) -> list[str]:
        return list(blocks)

    def ok(self, state: WorldState, rel: Relations, block: str) -> bool:
        raise NotImplementedError

    def moves(self, state: WorldState, block: str, variant: int) -> Iterable[Skill]:
        raise NotImplementedError

    def score(self, state: WorldState) -> float:
        group = self.group(state.blocks)
        if not group:
            return 0.0
        rel = relations(state)
        return sum(self.ok(state, rel, b) for b in group) / len(group)

    def satisfied(self, state: WorldState) -> bool:
        return bool(self.group(state.blocks)) and self.score(state) == 1.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if before.positions == after.positions:  # the step failed: nothing moved
            return False
        if self.score(after) < self.score(before) - 1e-9:
            return True
        return step.block in self.group(after.blocks) and not self.ok(after, relations(after), step.block)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        for _ in range(1000):
            n_blocks = int(rng.integers(2, 4))
            scene = sample_scene(rng, n_blocks=n_blocks, n_bowls=(1, 5 - n_blocks))
            if self.feasible(scene):
                return scene
        raise ValueError(f"no feasible scene found for {self.name!r}")

    def prepare(self, state: WorldState) -> list[Skill] | None:
        """Steps needed before the blocks can be placed (none by default)."""
        return []

    def plan(self, state: WorldState) -> list[Skill] | None:
        for variant in range(self.variants):
            if (steps := self.plan_variant(state, variant)) is not None:
                return steps
        return None

    def plan_variant(self, state: WorldState, variant: int) -> list[Skill] | None:
        steps = self.prepare(state)
        if steps is None:
            return None
        current = apply_plan(state, steps)[0][-1] if steps else state
        # Highest blocks first, so that nothing is picked up from under another block.
        for block in sorted(self.group(state.blocks), key=lambda b: -current.pos(b)[2]):
            if self.ok(current, relations(current), block):
                continue
            for step in self.moves(current, block, variant):
                after, failure = apply_skill(current, step)
                if failure is None and self.ok(after, relations(after), block):
                    current = after
                    steps.append(step)
                    break
            else:
                return None
        return steps if self.satisfied(current) else None


class InPinkBowl(_PerBlockRule):
    name = "all-in-pink-bowl"
    description = "Put every block in the pink bowl."

    def ok(self, state: WorldState, rel: Relations, block: str) -> bool:
        return rel.in_bowl(block) == "pink bowl"

    def moves(self, state: WorldState, block: str, variant: int) -> list[Skill]:
        return [PutIn(block=block, bowl="pink bowl")]

    def feasible(self, scene: Scene) -> bool:
        return "pink bowl" in scene.bowls and len(scene.blocks) >= 1


class AroundYellowBlock(_PerBlockRule):
    name = "around-the-yellow-block"
    description = "Put every other block on the table right next to the yellow block."

    hub = "yellow block"

    def group(self, blocks: list[str]) -> list[str]:
        return [b for b in blocks if b != self.hub]

    def ok(self, state: WorldState, rel: Relations, block: str) -> bool:
        return rel.is_next_to(block, self.hub) and _flat(rel, block)

    def moves(self, state: WorldState, block: str, variant: int) -> list[Skill]:
        centre = state.pos(self.hub)[:2]
        # "Next to" means footprints less than 5 cm apart: a ring of spots around the block.
        ring = [
            PutAt(block=block, position=(float(centre[0] + r * np.cos(a)), float(centre[1] + r * np.sin(a))))
            for r in (0.055, 0.07, 0.085)
            for a in np.linspace(0, 2 * np.pi, 16, endpoint=False)
        ]
        return [PutNextTo(block=block, target=self.hub), *ring]

    def prepare(self, state: WorldState) -> list[Skill] | None:
        # A yellow block in a bowl or on another block is first set down on the table.
        rel = relations(state)
        if self.hub not in state.positions or _on_table(rel, self.hub):
            return []
        if rel.above(self.hub):
            return None  # buried in a bowl or a stack: an untidy start this example skips
        for spot in _nearest(_grid((-0.2, 0.2), (-0.7, -0.3), 0.04), (0.0, -0.5)):
            after, failure = apply_skill(state, PutAt(block=self.hub, position=spot))
            if failure is None and _roomy(after, self.hub):
                return [PutAt(block=self.hub, position=spot)]
        return None

    def feasible(self, scene: Scene) -> bool:
        return self.hub in scene.blocks and 1 <= len(self.group(scene.blocks)) <= 4


class _TableRegion(_PerBlockRule):
    """Every block on the table (not in a bowl, not on a block) inside a region."""

    def inside(self, block: str, xy) -> bool:
        raise NotImplementedError

    def spots(self, state: WorldState, block: str, variant: int) -> list[tuple[float, float]]:
        raise NotImplementedError

    def ok(self, state: WorldState, rel: Relations, block: str) -> bool:
        return _on_table(rel, block) and self.inside(block, state.pos(block)[:2])

    def moves(self, state: WorldState, block: str, variant: int) -> Iterator[Skill]:
        for spot in self.spots(state, block, variant):
            step = PutAt(block=block, position=spot)
            after, failure = apply_skill(state, step)
            if failure is None and _roomy(after, block):
                yield step

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1


class OnLeftSide(_TableRegion):
    name = "all-on-left-side"
    description = (
        "Put every block on the table at the left side of the table, the middle of the left "
        "edge (not a corner)."
    )

    def inside(self, block: str, xy) -> bool:
        return table_position_name(xy) == "left side"

    # Fill the cell from its middle, or (when a bowl stands there) from one of its corners.
    ANCHORS = ((-0.2, -0.5), (-0.28, -0.42), (-0.28, -0.58), (-0.12, -0.42), (-0.12, -0.58))
    variants = len(ANCHORS)

    def spots(self, state: WorldState, block: str, variant: int) -> list[tuple[float, float]]:
        # The left-side cell is x < -0.1, -0.6 < y <= -0.4; keep 2 cm inside it.
        left = BOUNDS[0][0]
        return _nearest(_grid((left + 0.02, -0.12), (-0.58, -0.42)), self.ANCHORS[variant])


class WarmLeftHalfCoolRightHalf(_TableRegion):
    name = "warm-left-half-cool-right-half"
    description = (
        "Put the warm-coloured blocks on the left half of the table and the cool-coloured "
        "blocks on the right half."
    )

    def inside(self, block: str, xy) -> bool:
        return xy[0] < 0 if _is_warm(block) else xy[0] > 0

    def spots(self, state: WorldState, block: str, variant: int) -> list[tuple[float, float]]:
        (x0, x1), (y0, y1) = BOUNDS
        xs = (x0 + 0.02, -0.05) if _is_warm(block) else (0.05, x1 - 0.02)
        return _nearest(_grid(xs, (y0 + 0.02, y1 - 0.02), 0.03), state.pos(block)[:2])

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if _is_warm(b)]
        return bool(warm) and len(warm) < len(scene.blocks)


PINK_BOWL = InPinkBowl()
NEXT_TO_YELLOW = AroundYellowBlock()
LEFT_SIDE = OnLeftSide()
WARM_LEFT_COOL_RIGHT = WarmLeftHalfCoolRightHalf()
