"""The dev suite: 10 hidden intentions of the kind people ask a tabletop robot for, used to
tune learners (``--suite dev``). The held-out suite is never used for tuning; these were
written without looking at it. Six first-draft intentions that came close in meaning to
held-out ones (judged by the project lead from the held-out names) were removed, so the suite
has 10. Names start with ``dev-`` so that they can never clash with a name of another suite
(``suites.resolve`` looks names up across suites).

Conventions follow the built-in library: "front" is the bottom side of the table (−y, the
side a block goes to with "in front of"), "left" is −x, warm / cool colours are
world.WARM_COLORS / COOL_COLORS, and every plan is checked with the symbolic world model
before it is returned.

What each intention means (what a state must satisfy, its score, which moves go against it) is
the goal language's (activeintent.goals): a node over all the blocks, with the options or the
unregistered node that say the intention's own reading. Scenes and oracle plans are the
protocol's and stay here.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

import numpy as np

from activeintent.goals.facts import facts, is_warm
from activeintent.goals.relations import InBowl, OnBlock
from activeintent.goals.selectors import ColourClass
from activeintent.goals.structures import (
    EDGE,
    RED_TO_PURPLE,
    SEVEN_RAINBOW_COLOURS,
    AroundBowl,
    ClassGroupsApart,
    Cluster,
    Column,
    LineWithin,
    Row,
    SameCorner,
    SeparateBowls,
    TowerByBowl,
    along_left_edge,
    in_order,
)
from activeintent.intentions.base import Intention
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.placement import (
    TABLE_INNER,
    free_spot,
    grid,
    is_clear,
    nearest_first,
    on_table,
    top_first,
    towers,
    verified,
)
from activeintent.world import (
    BOUNDS,
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
from activeintent.world.scene import ROW_PITCH, color_of
from activeintent.world.skills import SIDES, TABLE_POSITIONS

CENTRE = np.array([0.0, -0.5])
CELL_CORNERS = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")
NEXT_TO_SIDES = ("nearest", *SIDES)


# --- scenes ------------------------------------------------------------------------------


def _pick(rng: np.random.Generator, n: int, pool: Iterable[str] = COLOR_NAMES, exclude: Iterable[str] = ()) -> list[str]:
    """``n`` distinct colours from ``pool`` (in palette order, so draws are reproducible)."""
    pool, exclude = set(pool), set(exclude)
    choices = [c for c in COLOR_NAMES if c in pool and c not in exclude]
    return [str(c) for c in rng.choice(choices, size=n, replace=False)] if n else []


def _scene(blocks: list[str], bowls: list[str]) -> Scene:
    return Scene(objects=[f"{c} block" for c in blocks] + [f"{c} bowl" for c in bowls])


def _warm_and_cool(rng: np.random.Generator, n_warm: int, n_cool: int) -> list[str]:
    blocks = _pick(rng, n_warm, WARM_COLORS) + _pick(rng, n_cool, COOL_COLORS)
    rng.shuffle(blocks)
    return blocks


def _bowl_count(rng: np.random.Generator, n_blocks: int, most: int = 2) -> int:
    """Bowls for a scene of 3–5 objects with ``n_blocks`` blocks (at most ``most``)."""
    low, high = max(0, 3 - n_blocks), min(most, 5 - n_blocks)
    return int(rng.integers(low, high + 1))


# --- planning helpers ----------------------------------------------------------------------


def _first_verified(intention: Intention, state: WorldState, plans: Iterable[list[Skill] | None]) -> list[Skill] | None:
    """The first candidate plan that the world model says satisfies ``intention``."""
    for steps in plans:
        if steps is not None and (found := verified(intention, state, steps)) is not None:
            return found
    return None


def _park(state: WorldState, block: str, accept: Callable[[WorldState], bool] | None = None) -> Skill | None:
    """Put ``block`` somewhere free on the table (not on a block, not in a bowl)."""

    def ok(after: WorldState) -> bool:
        return on_table(relations(after), block) and (accept is None or accept(after))

    spots = nearest_first(grid(*TABLE_INNER, step=0.05), state.pos(block)[:2])
    return free_spot(state, block, spots, accept=ok)


def _flatten(state: WorldState, keep: Iterable[str] = ()) -> tuple[list[Skill], WorldState] | None:
    """Park, top first, every block that rests on another block (except those in ``keep``)."""
    keep = set(keep)
    steps: list[Skill] = []
    for block in top_first(state, state.blocks):
        if block in keep or relations(state).below(block) is None:
            continue
        step = _park(state, block)
        if step is None:
            return None
        state, failure = apply_skill(state, step)
        if failure is not None:
            return None
        steps.append(step)
    return steps, state


def _greedy(state: WorldState, blocks: list[str], place: Callable[[WorldState, str], Skill | None]) -> list[Skill] | None:
    """Move ``blocks`` in order, each with the step ``place(current state, block)`` returns."""
    steps: list[Skill] = []
    for block in blocks:
        step = place(state, block)
        if step is None:
            return None
        state, failure = apply_skill(state, step)
        if failure is not None:
            return None
        steps.append(step)
    return steps


def _first_ok(state: WorldState, steps: Iterable[Skill], accept: Callable[[WorldState], bool]) -> Skill | None:
    """The first step the world model can do whose result ``accept`` likes."""
    for step in steps:
        after, failure = apply_skill(state, step)
        if failure is None and accept(after):
            return step
    return None


def _next_to_steps(block: str, target: str) -> list[Skill]:
    return [PutNextTo(block=block, target=target, side=side) for side in NEXT_TO_SIDES]  # type: ignore[arg-type]


def _ring(state: WorldState, centre_of: str, radii: tuple[float, ...] = (0.097, 0.11, 0.125)) -> list[tuple[float, float]]:
    c = state.pos(centre_of)[:2]
    return [
        (float(c[0] + r * np.cos(a)), float(c[1] + r * np.sin(a)))
        for r in radii
        for a in np.linspace(0, 2 * np.pi, 24, endpoint=False)
    ]


def _line_plans(
    state: WorldState,
    ordered: list[str],
    axis: int,
    along: tuple[float, float],
    across: tuple[float, float],
    step: float = 0.04,
) -> Iterator[list[Skill]]:
    """Plans putting ``ordered`` at explicit points of a straight line through free table space
    (increasing along ``axis``: 0 = x, 1 = y), lines nearest the table's centre first; the
    topmost blocks are moved first."""
    length = ROW_PITCH * (len(ordered) - 1)
    if along[1] - length < along[0]:
        return

    def xy(a: float, c: float) -> tuple[float, float]:
        return (a, c) if axis == 0 else (c, a)

    starts = [(a, c) for a, c in grid((along[0], along[1] - length), across, step=step)]
    starts.sort(key=lambda ac: float(np.hypot(*(np.array(xy(ac[0] + length / 2, ac[1])) - CENTRE))))
    for a, c in starts:
        points = {b: xy(a + i * ROW_PITCH, c) for i, b in enumerate(ordered)}
        yield [PutAt(block=b, position=points[b]) for b in top_first(state, ordered)]


def _components(rel: Relations, members: list[str]) -> list[list[str]]:
    """Groups of ``members`` linked by next-to relations, largest first."""
    left, groups = list(members), []
    while left:
        group, frontier = [left.pop(0)], None
        frontier = list(group)
        while frontier:
            a = frontier.pop()
            for b in [b for b in left if rel.is_next_to(a, b)]:
                left.remove(b)
                group.append(b)
                frontier.append(b)
        groups.append(group)
    return sorted(groups, key=len, reverse=True)


def _blocks_in(rel: Relations, bowl: str) -> list[str]:
    return [a for a, w in rel.inside if w == bowl]


def _nearest(state: WorldState, block: str, names: Iterable[str]) -> list[str]:
    here = state.pos(block)[:2]
    return sorted(names, key=lambda n: float(np.hypot(*(state.pos(n)[:2] - here))))


def _emptiest_bowls(state: WorldState, rel: Relations, block: str, bowls: Iterable[str]) -> list[str]:
    here = state.pos(block)[:2]
    return sorted(bowls, key=lambda w: (len(_blocks_in(rel, w)), float(np.hypot(*(state.pos(w)[:2] - here)))))


# --- 1. an ordered row ---------------------------------------------------------------------


def _rank(block: str) -> int | None:
    c = color_of(block)
    return SEVEN_RAINBOW_COLOURS.index(c) if c in SEVEN_RAINBOW_COLOURS else None


class RainbowRow(Intention):
    name = "dev-rainbow-row"
    description = (
        "Line the blocks up in one left-to-right row in rainbow order (red, orange, yellow, "
        "green, cyan, blue, purple)."
    )
    # A row of blocks resting on the table (loaded) in the order red to purple; a block set in
    # line beside one it should not be on that side of moves away (order_beside).
    node = Row(beside_any=True, loaded=True, order_beside=True)

    def ordered_row(self, state: WorldState, rel: Relations, members: Iterable[str]) -> bool:
        return self.node.line(facts(state), tuple(members), RED_TO_PURPLE)

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 2 and self.node.holds(facts(state), tuple(state.blocks), RED_TO_PURPLE)

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if not n:
            return 0.0
        f = facts(state)
        placeable = tuple(b for b in f.blocks if in_order((b,), RED_TO_PURPLE))  # pink, brown, gray never count
        return len(self.node.best(f, placeable, RED_TO_PURPLE)) / n

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, RED_TO_PURPLE)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2 and all(_rank(b) is not None for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 3 + int(rng.integers(0, 2))
        return _scene(_pick(rng, n_blocks, SEVEN_RAINBOW_COLOURS), _pick(rng, _bowl_count(rng, n_blocks, 1)))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        ordered = sorted(state.blocks, key=lambda b: _rank(b) or 0)

        def chains() -> Iterator[list[Skill]]:
            # Keep the first block where it stands and chain the others to its right, or keep
            # the last and chain the others to its left.
            yield [PutNextTo(block=b, target=a, side="right") for a, b in zip(ordered, ordered[1:], strict=False)]
            rev = ordered[::-1]
            yield [PutNextTo(block=b, target=a, side="left") for a, b in zip(rev, rev[1:], strict=False)]

        (x0, x1), (y0, y1) = TABLE_INNER
        return _first_verified(self, state, [*chains(), *_line_plans(state, ordered, 0, (x0, x1), (y0, y1))])


# --- 2. a table region --------------------------------------------------------------------


def _corner_cell(corner: str) -> tuple[tuple[float, float], tuple[float, float]]:
    """Points whose block stands in the corner's 20 cm cell (2 cm inside its edges)."""
    xs = (-0.28, -0.12) if "left" in corner else (0.12, 0.28)
    ys = (-0.38, -0.22) if corner.startswith("top") else (-0.78, -0.62)
    return xs, ys


class OneCorner(Intention):
    name = "dev-gather-in-one-corner"
    description = "Gather all the blocks together in one corner of the table, whichever corner you like."

    node = SameCorner()

    @classmethod
    def counts(cls, state: WorldState, rel: Relations) -> dict[str, int]:
        return cls.node.counts(facts(state), tuple(state.blocks))

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 1 and self.node.holds(facts(state), tuple(state.blocks), "")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 3))
        return _scene(_pick(rng, n_blocks), _pick(rng, _bowl_count(rng, n_blocks)))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if len(state.blocks) < 1:
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)
        counts = self.counts(state, rel)
        centroid = np.mean([state.pos(b)[:2] for b in state.blocks], axis=0)
        order = sorted(CELL_CORNERS, key=lambda c: (-counts[c], float(np.hypot(*(np.array(TABLE_POSITIONS[c]) - centroid)))))

        def into(corner: str) -> Callable[[WorldState, str], Skill | None]:
            def place(current: WorldState, block: str) -> Skill | None:
                r = relations(current)

                def ok(after: WorldState) -> bool:
                    return relations(after).table_position[block] == corner

                spots = [corner, *nearest_first(grid(*_corner_cell(corner), step=0.03), np.array(TABLE_POSITIONS[corner]))]
                if step := free_spot(current, block, spots, accept=ok):
                    return step
                onto = [PutOn(block=block, target=b) for b in current.blocks
                        if b != block and r.table_position[b] == corner and is_clear(r, b)]
                bowls = [PutIn(block=block, bowl=w) for w in current.bowls if r.table_position[w] == corner]
                return _first_ok(current, onto + bowls, ok)

            return place

        def candidates() -> Iterator[list[Skill] | None]:
            for corner in order:
                movers = top_first(state, [b for b in state.blocks if rel.table_position[b] != corner])
                yield _greedy(state, movers, into(corner))

        return _first_verified(self, state, candidates())


# --- 3–4. bowls: counts and colours --------------------------------------------------------


class AtMostTwoPerBowl(BlockwiseIntention):
    name = "dev-at-most-two-per-bowl"
    description = "Put every block in a bowl, with no more than two blocks in any one bowl."

    node = SeparateBowls(at_most=2)

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        return self.node.block_ok(f, f.blocks, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        room = [w for w in state.bowls if len(_blocks_in(rel, w)) < 2 and rel.in_bowl(block) != w]
        best = _emptiest_bowls(state, rel, block, room)
        return PutIn(block=block, bowl=best[0]) if best else None

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.blocks) <= 2 * len(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks, n_bowls = [(3, 2), (3, 2), (3, 2), (2, 1)][int(rng.integers(0, 4))]
        colors = _pick(rng, n_blocks + n_bowls)
        return _scene(colors[:n_blocks], colors[n_blocks:])


class SameWarmthBowls(BlockwiseIntention):
    name = "dev-warm-to-warm-bowls"
    description = (
        "Put each warm-coloured block in a warm-coloured bowl and each cool-coloured block in a "
        "cool-coloured bowl."
    )

    in_bowl = InBowl()

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return self.in_bowl.ok(facts(state), block, "same-class")

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        best = _emptiest_bowls(state, rel, block, [w for w in state.bowls if is_warm(w) == is_warm(block)])
        return PutIn(block=block, bowl=best[0]) if best else None

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and all(
            any(is_warm(w) == is_warm(b) for w in scene.bowls) for b in scene.blocks
        )

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm, n_cool = [(1, 1), (2, 1), (1, 2)][int(rng.integers(0, 3))]
        blocks = _warm_and_cool(rng, n_warm, n_cool)
        bowls = _pick(rng, 1, WARM_COLORS) + _pick(rng, 1, COOL_COLORS)
        rng.shuffle(bowls)
        return _scene(blocks, bowls)


# --- 5. stacking with a colour condition ----------------------------------------------------


class WarmOnCool(BlockwiseIntention):
    name = "dev-warm-on-cool"
    description = "Put each warm-coloured block on top of a cool-coloured block."

    classes = ColourClass()
    on_block = OnBlock()

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        return not self.classes.pick(block, f.bowls, "warm") or self.on_block.ok(f, block, "cool")

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        cool = [b for b in state.blocks if not is_warm(b) and is_clear(rel, b)]
        cool.sort(key=lambda b: (not on_table(rel, b), float(np.hypot(*(state.pos(b)[:2] - state.pos(block)[:2])))))
        return PutOn(block=block, target=cool[0]) if cool else None

    def feasible(self, scene: Scene) -> bool:
        warm = sum(is_warm(b) for b in scene.blocks)
        return 1 <= warm <= len(scene.blocks) - warm

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm, n_cool = [(1, 1), (1, 2), (1, 3), (2, 2)][int(rng.integers(0, 4))]
        blocks = _warm_and_cool(rng, n_warm, n_cool)
        return _scene(blocks, _pick(rng, _bowl_count(rng, len(blocks))))


# --- 6. a group ---------------------------------------------------------------------------


class BlocksTogether(Intention):
    name = "dev-blocks-together"
    description = "Gather all the blocks into one group on the table, each block right next to at least one other."

    # Blocks resting on the table (loaded), a moved block next to another one (touching).
    node = Cluster(touching=True, loaded=True)

    @staticmethod
    def groups(state: WorldState, rel: Relations) -> list[list[str]]:
        return _components(rel, [b for b in state.blocks if on_table(rel, b)])

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 2 and self.node.holds(facts(state), tuple(state.blocks), "")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        # A lone block has no other to be next to (the node lets a group of one stand alone).
        return len(after.blocks) == 1 or not self.node.moved_ok(
            facts(before), facts(after), tuple(after.blocks), step.block, "")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 3 + int(rng.integers(0, 2))
        return _scene(_pick(rng, n_blocks), _pick(rng, _bowl_count(rng, n_blocks)))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if len(state.blocks) < 2:
            return None
        if self.satisfied(state):
            return []

        def candidates() -> Iterator[list[Skill] | None]:
            flat = _flatten(state)
            if flat is None:
                return
            prefix, start = flat
            rel = relations(start)
            groups = self.groups(start, rel)
            flat_blocks = [b for b in start.blocks if on_table(rel, b)]
            anchors = [groups[0]] + [[b] for b in _nearest_to_centre(start, flat_blocks)] if groups else [[]]
            for group in anchors:
                steps, current, members = list(prefix), start, list(group)
                movers = top_first(current, [b for b in current.blocks if b not in members])
                if not members:  # nothing on the table: bring one block out first
                    first = movers.pop(0)
                    step = _park(current, first)
                    if step is None:
                        continue
                    current, _ = apply_skill(current, step)
                    steps.append(step)
                    members = [first]
                for b in movers:

                    def ok(after: WorldState, b: str = b, members: list[str] = members) -> bool:
                        r = relations(after)
                        return on_table(r, b) and any(r.is_next_to(b, m) for m in members)

                    tries = [s for m in _nearest(current, b, members) for s in _next_to_steps(b, m)]
                    step = _first_ok(current, tries, ok)
                    if step is None:
                        break
                    current, _ = apply_skill(current, step)
                    steps.append(step)
                    members.append(b)
                else:
                    yield steps

        return _first_verified(self, state, candidates())


def _nearest_to_centre(state: WorldState, blocks: list[str]) -> list[str]:
    return sorted(blocks, key=lambda b: float(np.hypot(*(state.pos(b)[:2] - CENTRE))))


# --- 7–8. next to bowls ----------------------------------------------------------------------


class AroundOneBowl(BlockwiseIntention):
    name = "dev-blocks-around-a-bowl"
    description = "Put all the blocks on the table around one bowl, each of them right next to that bowl."

    node = AroundBowl(loaded=True)  # blocks resting on the table, another may stand on one

    @classmethod
    def target(cls, state: WorldState, rel: Relations) -> str | None:
        """The bowl with the most blocks next to it (ties: the first listed)."""
        return cls.node.target(facts(state), tuple(state.blocks))

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        f = facts(state)
        return self.node.block_ok(f, f.blocks, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        bowl = self.target(state, rel)
        return self.place_at(state, block, bowl) if bowl else None

    @staticmethod
    def place_at(state: WorldState, block: str, bowl: str) -> Skill | None:
        def ok(after: WorldState) -> bool:
            r = relations(after)
            return on_table(r, block) and r.is_next_to(block, bowl)

        if step := _first_ok(state, _next_to_steps(block, bowl), ok):
            return step
        return free_spot(state, block, nearest_first(_ring(state, bowl), state.pos(block)[:2]), accept=ok)

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.blocks) <= 4 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        colors = _pick(rng, n_blocks + 1 + int(rng.integers(0, 2)))
        return _scene(colors[:n_blocks], colors[n_blocks:])

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks or not state.bowls:
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)

        def count(w: str) -> int:
            return sum(on_table(rel, b) and rel.is_next_to(b, w) for b in state.blocks)

        def candidates() -> Iterator[list[Skill] | None]:
            for bowl in sorted(state.bowls, key=lambda w: -count(w)):  # stable: ties as `target`
                movers = top_first(state, [b for b in state.blocks
                                           if not (on_table(rel, b) and rel.is_next_to(b, bowl))])
                yield _greedy(state, movers, lambda s, b, bowl=bowl: self.place_at(s, b, bowl))
            yield BlockwiseIntention.plan(self, state)

        return _first_verified(self, state, candidates())


class TowerBesideBowl(Intention):
    name = "dev-tower-beside-a-bowl"
    description = "Stack all the blocks into one tower standing on the table right next to a bowl."

    node = TowerByBowl()

    @classmethod
    def good(cls, state: WorldState, rel: Relations, tower: list[str]) -> bool:
        return tower in cls.node.by_bowl(facts(state), tuple(state.blocks))

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 2 and self.node.holds(facts(state), tuple(state.blocks), "any")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "any") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "any")

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        colors = _pick(rng, n_blocks + 1 + int(rng.integers(0, 2)))
        return _scene(colors[:n_blocks], colors[n_blocks:])

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []

        def stack_on(start: WorldState, keep: list[str], prefix: list[Skill]) -> list[Skill]:
            steps, top = list(prefix), keep[-1]
            for b in top_first(start, [b for b in start.blocks if b not in keep]):
                steps.append(PutOn(block=b, target=top))
                top = b
            return steps

        def candidates() -> Iterator[list[Skill] | None]:
            rel = relations(state)
            for tower in towers(state, rel):
                if self.good(state, rel, tower) and (flat := _flatten(state, tower)) is not None:
                    yield stack_on(flat[1], tower, flat[0])
            flat = _flatten(state)
            if flat is None:
                return
            prefix, start = flat
            near = sorted(start.blocks, key=lambda b: min(float(np.hypot(*(start.pos(b)[:2] - start.pos(w)[:2])))
                                                           for w in start.bowls))
            for base in near:
                for bowl in _nearest(start, base, start.bowls):
                    step = AroundOneBowl.place_at(start, base, bowl)
                    if step is not None:
                        after, _ = apply_skill(start, step)
                        yield stack_on(after, [base], [*prefix, step])

        return _first_verified(self, state, candidates())


# --- 9. a line in a region -------------------------------------------------------------------


# "Along the left edge": block centres at most 10 cm from the table's left edge (x = -0.3), so
# a column in the left third but nearer the middle of the table does not count
# (goals.structures.along_left_edge).
LEFT_EDGE_X = BOUNDS[0][0] + EDGE


def _by_left_edge(state: WorldState, block: str) -> bool:
    return along_left_edge(state.pos(block))


class LeftEdgeColumn(Intention):
    name = "dev-column-along-left-edge"
    description = "Line the blocks up front to back in one straight column along the left edge of the table."
    node = LineWithin(Column(loaded=True), along_left_edge, "left-edge", "along the left edge of the table")

    def column_ok(self, state: WorldState, rel: Relations, members: Iterable[str]) -> bool:
        return self.node.holds(facts(state), tuple(members), "any")

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 2 and self.node.holds(facts(state), tuple(state.blocks), "any")

    def score(self, state: WorldState) -> float:
        return self.node.score(facts(state), tuple(state.blocks), "any") if state.blocks else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return not self.node.moved_ok(facts(before), facts(after), tuple(after.blocks), step.block, "any")

    def feasible(self, scene: Scene) -> bool:
        return 2 <= len(scene.blocks) <= 4

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 3))
        return _scene(_pick(rng, n_blocks), _pick(rng, _bowl_count(rng, n_blocks)))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if len(state.blocks) < 2:
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)

        def chains() -> Iterator[list[Skill]]:
            anchors = [b for b in state.blocks if on_table(rel, b) and _by_left_edge(state, b)]
            for anchor in anchors:
                others = top_first(state, [b for b in state.blocks if b != anchor])
                for side in ("behind", "front"):
                    steps: list[Skill] = []
                    prev = anchor
                    for b in others:
                        steps.append(PutNextTo(block=b, target=prev, side=side))  # type: ignore[arg-type]
                        prev = b
                    yield steps

        ordered = sorted(state.blocks, key=lambda b: state.pos(b)[1])
        (_, _), (y0, y1) = TABLE_INNER
        lines = _line_plans(state, ordered, 1, (y0, y1), (TABLE_INNER[0][0], LEFT_EDGE_X - 0.02), step=0.02)
        return _first_verified(self, state, [*chains(), *lines])


# --- 10. two groups ---------------------------------------------------------------------------


class WarmAndCoolGroups(Intention):
    name = "dev-warm-and-cool-groups"
    description = (
        "Make two separate groups of blocks on the table, the warm-coloured blocks together in "
        "one and the cool-coloured blocks together in the other."
    )

    node = ClassGroupsApart()

    @classmethod
    def valid(cls, state: WorldState, rel: Relations, block: str) -> bool:
        """On the table and not touching a block of the other kind."""
        return cls.node.apart(facts(state), tuple(state.blocks), block)

    def groups(self, state: WorldState, rel: Relations, warm: bool) -> list[list[str]]:
        members = [b for b in state.blocks if is_warm(b) == warm and self.valid(state, rel, b)]
        return _components(rel, members)

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
        warm = sum(is_warm(b) for b in scene.blocks)
        return len(scene.blocks) >= 3 and 1 <= warm < len(scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm, n_cool = [(2, 2), (2, 2), (2, 1), (1, 2)][int(rng.integers(0, 4))]
        blocks = _warm_and_cool(rng, n_warm, n_cool)
        return _scene(blocks, _pick(rng, _bowl_count(rng, len(blocks))))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []

        def candidates() -> Iterator[list[Skill] | None]:
            flat = _flatten(state)
            if flat is None:
                return
            steps, current = list(flat[0]), flat[1]
            rel = relations(current)
            keep = {warm: (g[0] if (g := self.groups(current, rel, warm)) else []) for warm in (True, False)}
            movers = top_first(current, [b for b in current.blocks if b not in keep[True] + keep[False]])
            for b in movers:
                own = keep[is_warm(b)]

                def ok(after: WorldState, b: str = b, own: list[str] = own) -> bool:
                    r = relations(after)
                    return self.valid(after, r, b) and (not own or any(r.is_next_to(b, m) for m in own))

                if own:
                    step = _first_ok(current, [s for m in _nearest(current, b, own) for s in _next_to_steps(b, m)], ok)
                elif ok(current):  # the first of its kind, already apart from the others
                    own.append(b)
                    continue
                else:  # the first of its kind: anywhere on the table away from the others
                    step = _park(current, b, accept=ok)
                if step is None:
                    return
                current, _ = apply_skill(current, step)
                steps.append(step)
                own.append(b)
            yield steps

        return _first_verified(self, state, candidates())


def dev_intentions() -> list[Intention]:
    """One fresh instance of every dev intention, in a fixed order."""
    return [
        RainbowRow(),
        OneCorner(),
        AtMostTwoPerBowl(),
        SameWarmthBowls(),
        WarmOnCool(),
        BlocksTogether(),
        AroundOneBowl(),
        TowerBesideBowl(),
        LeftEdgeColumn(),
        WarmAndCoolGroups(),
    ]

