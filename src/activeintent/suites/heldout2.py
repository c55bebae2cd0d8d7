"""Held-out suite 2 (``--suite heldout2``): 24 natural requests to a tabletop robot, names ``h2-…``.

Who and how. Written by a helper session (an AI coding agent) that the project's main session
started for this purpose, in the worktree ``wt-heldout2``, *blind*: before writing it the author
read only the world model (``activeintent.world``: scene, state, relations, skills, predict),
the intention library and its helpers (``activeintent.intentions``: base, placement, blockwise,
regions, bowls, arrangements, registry), ``suites.py``, ``protocol.py``'s scene samplers,
docs/intentions.md, the suites section of docs/protocol.md, the shared design notes and the
intention tests; never a learner, the other held-out or the dev suite's code, the learners' goal
language, or any result. Nothing here is imported from
``activeintent.learners``; the intentions are built from the world's helpers and the intention
helpers only, and no learner or benchmark was run on them before they were committed. The
requests are phrased as study participants phrase them (particular objects, orderings, each
block's own bowl, exceptions, exact counts, structures at a place, pairs, "leave everything else
where it is", two clauses), not chosen for what some learner could represent. Intentions close
to the dev suite's (whose names docs/protocol.md lists: a rainbow row, warm blocks on cool ones,
a column along the left edge, …) were left out on purpose, so that tuning on dev does not tune
on these.

Conventions (from world/scene.py, world/skills.py and world/relations.py):

- x runs left → right (−0.3 … 0.3 m), y front → back (−0.8 … −0.2 m), z up; "in front of" is
  −y (skills' ``side="front"``), "behind" +y; the *back edge* is the table's top side
  (y = −0.2), the *front edge* its bottom side (y = −0.8); "the front right corner" is the table
  position "bottom right corner".
- "On the table" is ``placement.on_table`` (resting directly on the table, not in a bowl, not on
  a block); a *tower* is a standing tower (``placement.standing_towers``: its base on the table;
  blocks piled in a bowl are in the bowl, not a tower); a *row* is ``Align.line_ok`` (one
  straight left-to-right line on the table, neighbours next to each other, the other coordinate
  within 2 cm); "next to" is ``relations().is_next_to`` (footprints under 5 cm apart).
- "The bowl furthest to the left / right" is the bowl of least / greatest x (bowls never move).
- "Leave everything else where it is": ``satisfied`` sees only the final state, so there it
  means every other block still stands on the table by itself (not in a bowl, not stacked, as
  every block of an initial layout does); ``step_moves_away`` says it exactly: any executed
  step that moves another block moves away.
- ``score`` is a fraction of the blocks placed as wanted, and 1.0 exactly when ``satisfied``
  (a partial fraction is capped below 1).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from itertools import combinations, permutations

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.lines import StraightLine as Align
from activeintent.intentions.placement import (
    LINE_TOL,
    TABLE_INNER,
    free_spot,
    grid,
    is_clear,
    is_warm,
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
from activeintent.world.scene import ROW_PITCH, color_of

BACK_Y = -0.31  # a block "along the back edge": centre within 11 cm of it (y = -0.2)
FRONT_Y = -0.69  # a block "along the front edge": centre within 11 cm of it (y = -0.8)
_ROW = Align()  # its line_ok is the row every row request here means


# --- small helpers --------------------------------------------------------------------------


def _colors(rng: np.random.Generator, n: int, pool: Iterable[str] = COLOR_NAMES,
            exclude: Iterable[str] = ()) -> list[str]:
    options = [c for c in sorted(pool) if c not in set(exclude)]
    return [str(c) for c in rng.choice(options, size=n, replace=False)]


def _scene(rng: np.random.Generator, blocks: list[str], bowls: list[str]) -> Scene:
    order = [blocks[i] for i in rng.permutation(len(blocks))]
    return Scene(objects=[f"{c} block" for c in order] + [f"{c} bowl" for c in bowls])


def _cap(fraction: float, n: int) -> float:
    """A partial score: never 1.0 unless the intention is satisfied."""
    return float(min(max(fraction, 0.0), 1.0 - 0.5 / max(n, 1)))


def _warm(scene_or_state) -> list[str]:
    return [b for b in scene_or_state.blocks if is_warm(b)]


def _cool(scene_or_state) -> list[str]:
    return [b for b in scene_or_state.blocks if not is_warm(b)]


def _own_bowl(block: str) -> str:
    return f"{color_of(block)} bowl"


def _contents(rel: Relations, bowl: str) -> list[str]:
    return [a for a, w in rel.inside if w == bowl]


def _alone_on_table(rel: Relations, block: str) -> bool:
    return on_table(rel, block) and is_clear(rel, block)


def _leftmost_bowl(state: WorldState) -> str | None:
    return min(state.bowls, key=lambda w: state.pos(w)[0]) if state.bowls else None


def _rightmost_bowl(state: WorldState) -> str | None:
    return max(state.bowls, key=lambda w: state.pos(w)[0]) if state.bowls else None


def _nearest_bowls(state: WorldState, block: str) -> list[str]:
    here = state.pos(block)[:2]
    return sorted(state.bowls, key=lambda w: float(np.hypot(*(state.pos(w)[:2] - here))))


def _in_front_of(state: WorldState, rel: Relations, block: str, bowl: str | None) -> bool:
    """On the table, next to ``bowl`` and in front of it (within 45° of straight ahead)."""
    if bowl is None or bowl not in state.positions or not on_table(rel, block):
        return False
    if not rel.is_next_to(block, bowl):
        return False
    dx, dy = state.pos(block)[:2] - state.pos(bowl)[:2]
    return bool(dy < 0 and abs(dx) <= -dy)


def _front_step(state: WorldState, block: str, bowl: str, accept: Callable[[WorldState], bool]) -> Skill | None:
    """A skill that sets ``block`` down in front of ``bowl`` (straight ahead first)."""
    step = PutNextTo(block=block, target=bowl, side="front")
    after, failure = apply_skill(state, step)
    if failure is None and accept(after):
        return step
    cx, cy = state.pos(bowl)[:2]
    angles = sorted(np.linspace(-0.75 * np.pi, -0.25 * np.pi, 11), key=lambda a: abs(a + np.pi / 2))
    ring = [(float(cx + r * np.cos(a)), float(cy + r * np.sin(a))) for a in angles for r in (0.097, 0.108)]
    return free_spot(state, block, ring, accept=accept)


def _largest(members: list[str], ok: Callable[[tuple[str, ...]], bool]) -> int:
    """Size of the largest subset of ``members`` for which ``ok`` holds (0 if none)."""
    for size in range(len(members), 0, -1):
        if any(ok(c) for c in combinations(members, size)):
            return size
    return 0


def _line(state: WorldState, rel: Relations, members: Iterable[str]) -> bool:
    members = list(members)
    return bool(members) and _ROW.line_ok(state, rel, members)


class _Steps:
    """A plan under construction, with the state the world model predicts after it."""

    def __init__(self, state: WorldState):
        self.state, self.steps, self.ok = state, [], True

    def do(self, step: Skill | None) -> bool:
        if not self.ok or step is None:
            self.ok = False
            return False
        after, failure = apply_skill(self.state, step)
        if failure is not None:
            self.ok = False
            return False
        self.state = after
        self.steps.append(step)
        return True

    def clear(self, block: str) -> bool:
        """Set every block above ``block`` down on the table, topmost first."""
        for _ in range(len(self.state.blocks)):
            rel = relations(self.state)
            top = block
            while (up := rel.above(top)) is not None:
                top = up
            if top == block:
                return self.ok
            self.do(park(self.state, top))
        return self.ok


def _first_verified(intention: Intention, state: WorldState, candidates: Iterable[list[Skill]],
                    limit: int = 3000) -> list[Skill] | None:
    """The first candidate plan that satisfies ``intention`` with no step moving away from it,
    else the first that satisfies it at all."""
    fallback = None
    for i, steps in enumerate(candidates):
        if i >= limit:
            break
        if verified(intention, state, steps) is None:
            continue
        if not _moves_away_somewhere(intention, state, steps):
            return steps
        fallback = fallback or steps
    return fallback


def _moves_away_somewhere(intention: Intention, state: WorldState, steps: list[Skill]) -> bool:
    current = state
    for step in steps:
        after, failure = apply_skill(current, step)
        if failure is None and intention.step_moves_away(current, after, step):
            return True
        current = after
    return False


def _shortest(intention: Intention, state: WorldState, candidates: Iterable[list[Skill] | None]) -> list[Skill] | None:
    good = [c for c in candidates if c is not None and verified(intention, state, c) is not None]
    clean = [c for c in good if not _moves_away_somewhere(intention, state, c)]
    pool = clean or good
    return min(pool, key=len) if pool else None


def _build_tower(state: WorldState, order: list[str], base_ok: Callable[[WorldState, str], bool] | None = None,
                 base_spots: list | None = None) -> list[Skill] | None:
    """Steps that leave ``order`` (bottom first) standing as one tower, keeping the part of it
    that already stands; the base is set down where ``base_ok`` holds."""
    plan = _Steps(state)
    rel = relations(state)
    kept = 0
    if on_table(rel, order[0]) and (base_ok is None or base_ok(state, order[0])):
        kept = 1
        while kept < len(order) and rel.above(order[kept - 1]) == order[kept]:
            kept += 1
    if kept:
        plan.clear(order[kept - 1])
    for i in range(kept, len(order)):
        block = order[i]
        plan.clear(block)
        if not plan.ok:
            return None
        if i == 0:
            here = plan.state.pos(block)[:2]
            spots = base_spots or nearest_first(grid(*TABLE_INNER, step=0.05), here)

            def accept(after: WorldState, block: str = block) -> bool:
                return on_table(relations(after), block) and (base_ok is None or base_ok(after, block))

            plan.do(free_spot(plan.state, block, spots, accept=accept))
        else:
            plan.do(PutOn(block=block, target=order[i - 1]))
    return plan.steps if plan.ok else None


def _row_candidates(state: WorldState, orders: list[list[str]], ys: Iterable[float]) -> Iterator[list[Skill]]:
    """Plans that put each order's blocks into a left-to-right row: chained beside the first
    (or the last) block where it stands, else at the points of a line at height y."""
    for order in orders:
        yield [PutNextTo(block=b, target=a, side="right") for a, b in zip(order, order[1:], strict=False)]
        back = order[::-1]
        yield [PutNextTo(block=b, target=a, side="left") for a, b in zip(back, back[1:], strict=False)]
    if not orders:
        return
    n = len(orders[0])
    length = ROW_PITCH * (n - 1)
    (x0, x1), _ = TABLE_INNER
    starts = sorted(np.arange(x0, x1 - length + 1e-9, 0.02), key=lambda s: abs(s + length / 2))
    for y in ys:
        for start in starts:
            for order in orders:
                points = {b: (float(start + i * ROW_PITCH), float(y)) for i, b in enumerate(order)}
                yield [PutAt(block=b, position=points[b]) for b in top_first(state, order)]


def _row_step_away(after: WorldState, block: str, members: list[str]) -> bool:
    """``block`` (a row member) was set down where no row of ``members`` goes on: not on the
    table, or beside members of which it is in line with none."""
    rel = relations(after)
    if not on_table(rel, block):
        return True
    y = after.pos(block)[1]
    neighbours = [o for o in members if o != block and on_table(rel, o) and rel.is_next_to(block, o)]
    return bool(neighbours) and all(abs(after.pos(o)[1] - y) > LINE_TOL for o in neighbours)


# --- particular objects -----------------------------------------------------------------------


class _NamedBlock(Intention):
    """A request about one named block (the others are free, or must be left alone)."""

    colour = ""
    others_stay = False
    min_blocks = 1
    needs_bowl = True

    @property
    def block(self) -> str:
        return f"{self.colour} block"

    def ok(self, state: WorldState, rel: Relations) -> bool:
        raise NotImplementedError

    def half(self, state: WorldState, rel: Relations) -> bool:
        """A near miss (worth half a block)."""
        return False

    def candidates(self, state: WorldState) -> Iterable[Skill | None]:
        raise NotImplementedError

    def satisfied(self, state: WorldState) -> bool:
        if self.block not in state.positions:
            return False
        rel = relations(state)
        if not self.ok(state, rel):
            return False
        return not self.others_stay or all(_alone_on_table(rel, b) for b in state.blocks if b != self.block)

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        if self.block not in state.positions:
            return 0.0
        rel = relations(state)
        mine = 1.0 if self.ok(state, rel) else 0.5 if self.half(state, rel) else 0.0
        if not self.others_stay:
            return _cap(mine, 2)
        others = sum(_alone_on_table(rel, b) for b in state.blocks if b != self.block)
        return _cap((mine + others) / len(state.blocks), len(state.blocks))

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block == self.block:
            return not self.ok(after, relations(after))
        return self.others_stay

    def feasible(self, scene: Scene) -> bool:
        return (self.block in scene.blocks and len(scene.blocks) >= self.min_blocks
                and (bool(scene.bowls) or not self.needs_bowl))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.block not in state.positions:
            return None
        if self.satisfied(state):
            return []
        prep = _Steps(state)
        if self.others_stay:  # from a state no layout gives: set the other blocks down alone first
            for b in top_first(state, [b for b in state.blocks if b != self.block]):
                if not _alone_on_table(relations(prep.state), b):
                    prep.clear(b)
                    prep.do(park(prep.state, b))
        if not prep.clear(self.block):
            return None
        for step in self.candidates(prep.state):
            if step is not None and (found := verified(self, state, [*prep.steps, step])):
                return found
        return None

    def _sample(self, rng: np.random.Generator, n_blocks: int, n_bowls: int) -> Scene:
        others = _colors(rng, n_blocks - 1, exclude=(self.colour,))
        return _scene(rng, [self.colour, *others], _colors(rng, n_bowls))


class RedInFrontOfLeftBowl(_NamedBlock):
    name = "h2-red-in-front-of-left-bowl"
    description = "Put the red block on the table just in front of the bowl that is furthest to the left."
    colour = "red"

    def ok(self, state: WorldState, rel: Relations) -> bool:
        return _in_front_of(state, rel, self.block, _leftmost_bowl(state))

    def half(self, state: WorldState, rel: Relations) -> bool:
        left = _leftmost_bowl(state)
        return on_table(rel, self.block) and (
            rel.is_next_to(self.block, left) or any(_in_front_of(state, rel, self.block, w) for w in state.bowls)
        )

    def candidates(self, state: WorldState) -> Iterable[Skill | None]:
        left = _leftmost_bowl(state)
        if left is not None:
            yield _front_step(state, self.block, left, accept=lambda s: self.ok(s, relations(s)))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        return self._sample(rng, n_blocks, 2 if rng.random() < 0.75 else 1)


class BlueOnAnotherBlock(_NamedBlock):
    name = "h2-blue-on-another-block"
    description = "Put the blue block on top of one of the other blocks."
    colour = "blue"
    min_blocks = 2
    needs_bowl = False

    def ok(self, state: WorldState, rel: Relations) -> bool:
        return rel.below(self.block) is not None

    def candidates(self, state: WorldState) -> Iterable[Skill | None]:
        rel = relations(state)
        here = state.pos(self.block)[:2]
        targets = [b for b in state.blocks if b != self.block and is_clear(rel, b)]
        for t in sorted(targets, key=lambda b: float(np.hypot(*(state.pos(b)[:2] - here)))):
            yield PutOn(block=self.block, target=t)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        return self._sample(rng, n_blocks, 1 + int(rng.integers(0, 2)))


class GreenInRightBowl(_NamedBlock):
    name = "h2-green-in-right-bowl"
    description = "Put the green block in the bowl furthest to the right."
    colour = "green"

    def ok(self, state: WorldState, rel: Relations) -> bool:
        right = _rightmost_bowl(state)
        return right is not None and rel.in_bowl(self.block) == right

    def half(self, state: WorldState, rel: Relations) -> bool:
        return rel.in_bowl(self.block) is not None

    def candidates(self, state: WorldState) -> Iterable[Skill | None]:
        right = _rightmost_bowl(state)
        if right is not None:
            yield PutIn(block=self.block, bowl=right)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        n_bowls = 2 + int(rng.integers(0, 2)) if n_blocks == 2 else 2
        return self._sample(rng, n_blocks, n_bowls)


class PurpleInBowlLeaveRest(_NamedBlock):
    name = "h2-purple-in-bowl-leave-rest"
    description = "Put the purple block in a bowl and leave everything else where it is."
    colour = "purple"
    others_stay = True

    def ok(self, state: WorldState, rel: Relations) -> bool:
        return rel.in_bowl(self.block) is not None

    def candidates(self, state: WorldState) -> Iterable[Skill | None]:
        for bowl in _nearest_bowls(state, self.block):
            yield PutIn(block=self.block, bowl=bowl)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 3))
        return self._sample(rng, n_blocks, 1 if n_blocks == 4 else 1 + int(rng.integers(0, 2)))


FRONT_RIGHT = "bottom right corner"  # the front right corner (front = -y = the bottom side)


class CyanToFrontRightCornerLeaveRest(_NamedBlock):
    name = "h2-cyan-to-front-right-corner-leave-rest"
    description = (
        "Move the cyan block to the front right corner of the table and leave everything else "
        "where it is."
    )
    colour = "cyan"
    others_stay = True
    needs_bowl = False
    min_blocks = 2

    def ok(self, state: WorldState, rel: Relations) -> bool:
        return on_table(rel, self.block) and rel.table_position.get(self.block) == FRONT_RIGHT

    def half(self, state: WorldState, rel: Relations) -> bool:
        return on_table(rel, self.block) and rel.table_position.get(self.block) in ("bottom side", "right side")

    def candidates(self, state: WorldState) -> Iterable[Skill | None]:
        cell = grid((0.12, 0.28), (-0.78, -0.62), step=0.03)
        spots = [FRONT_RIGHT, *nearest_first(cell, np.array([0.25, -0.75]))]
        yield free_spot(state, self.block, spots, accept=lambda s: self.ok(s, relations(s)))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        return self._sample(rng, n_blocks, 1 + int(rng.integers(0, 2)))


# --- towers with an order -------------------------------------------------------------------


class _OrderedTower(Intention):
    """One standing tower of every block, in an order the request gives."""

    min_blocks = 2

    def good_prefix(self, state: WorldState, rel: Relations, tower: list[str]) -> int:
        """How many blocks from the bottom of ``tower`` stand as the request wants."""
        raise NotImplementedError

    def orders(self, state: WorldState) -> list[list[str]]:
        blocks = state.blocks
        return [list(p) for p in permutations(blocks) if self._order_ok(state, list(p))]

    def _order_ok(self, state: WorldState, order: list[str]) -> bool:
        return self.good_prefix(state, None, order) == len(order)  # type: ignore[arg-type]

    base_ok: Callable[[WorldState, str], bool] | None = None
    base_spots: list | None = None

    def satisfied(self, state: WorldState) -> bool:
        n = len(state.blocks)
        rel = relations(state)
        ts = standing_towers(state, rel)
        return n >= 1 and len(ts) == 1 and len(ts[0]) == n and self.good_prefix(state, rel, ts[0]) == n

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        rel = relations(state)
        best = max((self.good_prefix(state, rel, t) for t in standing_towers(state, rel)), default=0)
        return _cap(best / n, n) if n else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        return not any(step.block in t[: self.good_prefix(after, rel, t)] for t in standing_towers(after, rel))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= self.min_blocks

    def plan(self, state: WorldState) -> list[Skill] | None:
        if len(state.blocks) < 1:
            return None
        if self.satisfied(state):
            return []
        spots = self.base_spots
        return _shortest(self, state, (_build_tower(state, o, self.base_ok, spots) for o in self.orders(state)))


def _any_scene(rng: np.random.Generator, n_blocks: int | None = None) -> Scene:
    """2-4 blocks (or ``n_blocks``) and up to 2 bowls, 3-5 objects, colours by chance."""
    n_blocks = n_blocks or 2 + int(rng.integers(0, 3))
    n_bowls = int(rng.integers(max(0, 3 - n_blocks), min(2, 5 - n_blocks) + 1))
    return _scene(rng, _colors(rng, n_blocks), _colors(rng, n_bowls))


class AlphabeticalTower(_OrderedTower):
    name = "h2-alphabetical-tower"
    description = "Stack all the blocks into one tower, in alphabetical order of their colours from the bottom up."

    def good_prefix(self, state: WorldState, rel: Relations | None, tower: list[str]) -> int:
        want = sorted(state.blocks, key=color_of)
        k = 0
        while k < len(tower) and tower[k] == want[k]:
            k += 1
        return k

    def orders(self, state: WorldState) -> list[list[str]]:
        return [sorted(state.blocks, key=color_of)]

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _any_scene(rng)


class WarmUnderCoolTower(_OrderedTower):
    name = "h2-warm-under-cool-tower"
    description = (
        "Build one tower of all the blocks with the warm-coloured ones at the bottom and the "
        "cool-coloured ones on top."
    )

    def good_prefix(self, state: WorldState, rel: Relations | None, tower: list[str]) -> int:
        n_warm = len(_warm(state))
        k = 0
        for b in tower:
            below = tower[:k]
            if is_warm(b) and any(not is_warm(x) for x in below):
                break
            if not is_warm(b) and sum(is_warm(x) for x in below) < n_warm:
                break
            k += 1
        return k

    def feasible(self, scene: Scene) -> bool:
        return bool(_warm(scene)) and bool(_cool(scene))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm = 1 + int(rng.integers(0, 2))
        n_cool = 1 + int(rng.integers(0, 2))
        blocks = _colors(rng, n_warm, WARM_COLORS) + _colors(rng, n_cool, COOL_COLORS)
        n_bowls = int(rng.integers(max(0, 3 - len(blocks)), min(2, 5 - len(blocks)) + 1))
        return _scene(rng, blocks, _colors(rng, n_bowls))


class OrangeAtBottomTower(_OrderedTower):
    name = "h2-orange-at-bottom-tower"
    description = "Stack all the blocks into one tower with the orange block at the bottom."

    def good_prefix(self, state: WorldState, rel: Relations | None, tower: list[str]) -> int:
        return len(tower) if tower and tower[0] == "orange block" else 0

    def feasible(self, scene: Scene) -> bool:
        return "orange block" in scene.blocks and len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        blocks = ["orange", *_colors(rng, n_blocks - 1, exclude=("orange",))]
        return _scene(rng, blocks, _colors(rng, 1 + int(rng.integers(0, 2))))


def _in_middle(state: WorldState, block: str) -> bool:
    return relations(state).table_position.get(block) == "middle"


class TowerInMiddle(_OrderedTower):
    name = "h2-tower-in-middle"
    description = "Build one tower of all the blocks in the middle of the table."
    base_ok = staticmethod(_in_middle)
    base_spots = ["middle", *nearest_first(grid((-0.08, 0.08), (-0.58, -0.42), step=0.02), np.array([0.0, -0.5]))]

    def good_prefix(self, state: WorldState, rel: Relations | None, tower: list[str]) -> int:
        if rel is None:  # an order to build: any order will do
            return len(tower)
        return len(tower) if tower and rel.table_position.get(tower[0]) == "middle" else 0

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _any_scene(rng)


# --- rows at a place or in an order ----------------------------------------------------------


class _Row(Intention):
    """All the blocks in one left-to-right row, with a condition on the row."""

    ys: tuple[float, ...] = tuple(float(y) for y in np.arange(-0.5, -0.26, 0.04)) + tuple(
        float(y) for y in np.arange(-0.54, -0.75, -0.04)
    )

    def row_ok(self, state: WorldState, rel: Relations, members: tuple[str, ...] | list[str]) -> bool:
        return _line(state, rel, members)

    def satisfied(self, state: WorldState) -> bool:
        return len(state.blocks) >= 1 and self.row_ok(state, relations(state), state.blocks)

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        rel = relations(state)
        return _cap(_largest(state.blocks, lambda c: self.row_ok(state, rel, c)) / n, n) if n else 0.0

    def orders(self, state: WorldState) -> list[list[str]]:
        return [list(top_first(state, state.blocks))]

    def extra_away(self, after: WorldState, block: str) -> bool:
        return False

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        return _row_step_away(after, step.block, after.blocks) or self.extra_away(after, step.block)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        return _first_verified(self, state, _row_candidates(state, self.orders(state), self.ys))


def _alternates(state: WorldState, members) -> bool:
    ordered = sorted(members, key=lambda b: state.pos(b)[0])
    return all(is_warm(a) != is_warm(b) for a, b in zip(ordered, ordered[1:], strict=False))


class AlternatingRow(_Row):
    name = "h2-alternating-row"
    description = "Line the blocks up in one left-to-right row so that warm and cool colours alternate."

    def row_ok(self, state: WorldState, rel: Relations, members) -> bool:
        return _line(state, rel, members) and _alternates(state, members)

    def orders(self, state: WorldState) -> list[list[str]]:
        return [list(p) for p in permutations(state.blocks)
                if all(is_warm(a) != is_warm(b) for a, b in zip(p, p[1:], strict=False))]

    def extra_away(self, after: WorldState, block: str) -> bool:
        rel = relations(after)
        y = after.pos(block)[1]
        in_line = [o for o in after.blocks if o != block and on_table(rel, o) and rel.is_next_to(block, o)
                   and abs(after.pos(o)[1] - y) <= LINE_TOL]
        return any(is_warm(o) == is_warm(block) for o in in_line)

    def feasible(self, scene: Scene) -> bool:
        w, c = len(_warm(scene)), len(_cool(scene))
        return w >= 1 and c >= 1 and abs(w - c) <= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm, n_cool = ((1, 1), (1, 2), (2, 1), (2, 2))[int(rng.integers(0, 4))]
        blocks = _colors(rng, n_warm, WARM_COLORS) + _colors(rng, n_cool, COOL_COLORS)
        n_bowls = int(rng.integers(max(0, 3 - len(blocks)), min(2, 5 - len(blocks)) + 1))
        return _scene(rng, blocks, _colors(rng, n_bowls))


class RowAlongBackEdge(_Row):
    name = "h2-row-along-back-edge"
    description = "Make one left-to-right row of all the blocks along the back edge of the table."
    ys = (-0.24, -0.26, -0.28, -0.30)

    def row_ok(self, state: WorldState, rel: Relations, members) -> bool:
        return _line(state, rel, members) and all(state.pos(b)[1] >= BACK_Y for b in members)

    def extra_away(self, after: WorldState, block: str) -> bool:
        return after.pos(block)[1] < BACK_Y

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _any_scene(rng)


# --- each block and its own bowl ---------------------------------------------------------------


class InFrontOfOwnBowl(BlockwiseIntention):
    name = "h2-in-front-of-own-bowl"
    description = "Put each block on the table right in front of the bowl of its own colour."

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return _in_front_of(state, rel, block, _own_bowl(block))

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        bowl = _own_bowl(block)
        if bowl not in state.positions:
            return None
        return _front_step(state, block, bowl, accept=lambda s: self.wanted(s, relations(s), block))

    def feasible(self, scene: Scene) -> bool:
        return bool(scene.blocks) and all(_own_bowl(b) in scene.bowls for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        colours = _colors(rng, 2 + int(rng.integers(0, 2)))
        return _scene(rng, colours[:2], colours)


def _other_block_colours(state_or_scene, block: str) -> set[str]:
    return {color_of(o) for o in state_or_scene.blocks if o != block}


class IntoAnotherBlocksBowl(BlockwiseIntention):
    name = "h2-into-another-blocks-bowl"
    description = "Put each block into a bowl that has the colour of one of the other blocks."

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        bowl = rel.in_bowl(block)
        return bowl is not None and color_of(bowl) in _other_block_colours(state, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        options = [w for w in state.bowls if color_of(w) in _other_block_colours(state, block)]
        if not options:
            return None
        here = state.pos(block)[:2]
        best = min(options, key=lambda w: (len(_contents(rel, w)), float(np.hypot(*(state.pos(w)[:2] - here)))))
        return PutIn(block=block, bowl=best)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2 and all(
            any(f"{c} bowl" in scene.bowls for c in _other_block_colours(scene, b)) for b in scene.blocks
        )

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        if rng.random() < 0.6:  # two blocks, the bowls of their colours (and maybe one more)
            colours = _colors(rng, 2 + int(rng.integers(0, 2)))
            return _scene(rng, colours[:2], colours)
        blocks = _colors(rng, 3)  # three blocks, bowls of two of their colours
        return _scene(rng, blocks, blocks[:2])


class OwnBowlElseRightHalf(BlockwiseIntention):
    name = "h2-own-bowl-else-right-half"
    description = (
        "Put each block in the bowl of its colour if there is one, and put the other blocks on "
        "the right half of the table."
    )

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        bowl = _own_bowl(block)
        if bowl in state.positions:
            return rel.in_bowl(block) == bowl
        return on_table(rel, block) and state.pos(block)[0] > 0

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        bowl = _own_bowl(block)
        if bowl in state.positions:
            return PutIn(block=block, bowl=bowl)
        here = state.pos(block)[:2]
        named = ["right side", "top right corner", "bottom right corner"]
        spots = [*named, *nearest_first(grid((0.05, TABLE_INNER[0][1]), TABLE_INNER[1], step=0.04), here)]
        return free_spot(state, block, spots, accept=lambda s: self.wanted(s, relations(s), block))

    def feasible(self, scene: Scene) -> bool:
        return any(_own_bowl(b) in scene.bowls for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        if rng.random() < 0.5:  # two blocks with their bowls, one without
            colours = _colors(rng, 3)
            return _scene(rng, colours, colours[:2])
        colours = _colors(rng, 2 + int(rng.integers(0, 2)))  # one block with its bowl, others without
        extra = _colors(rng, int(rng.integers(0, 2)), exclude=colours)
        return _scene(rng, colours, [colours[0], *extra])


# --- exceptions -------------------------------------------------------------------------------


class AllButGreenInBowls(BlockwiseIntention):
    name = "h2-all-but-green-in-bowls"
    description = "Put all the blocks in bowls except the green one, which stays out on the table."
    green = "green block"

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        if block == self.green:
            return on_table(rel, block)
        return rel.in_bowl(block) is not None

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        if block == self.green:
            return self.park(state, block)
        bowls = _nearest_bowls(state, block)
        return PutIn(block=block, bowl=bowls[0]) if bowls else None

    def feasible(self, scene: Scene) -> bool:
        return self.green in scene.blocks and len(scene.blocks) >= 2 and bool(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        blocks = ["green", *_colors(rng, n_blocks - 1, exclude=("green",))]
        return _scene(rng, blocks, _colors(rng, 1 + int(rng.integers(0, 2))))


class AllButYellowTowerYellowInBowl(Intention):
    name = "h2-all-but-yellow-tower-yellow-in-bowl"
    description = "Stack every block except the yellow one into a tower, and put the yellow block in a bowl."
    yellow = "yellow block"

    def _rest(self, state: WorldState) -> list[str]:
        return [b for b in state.blocks if b != self.yellow]

    def _best_tower(self, state: WorldState, rel: Relations) -> int:
        best = 0
        for t in standing_towers(state, rel):
            k = 0
            while k < len(t) and t[k] != self.yellow:
                k += 1
            best = max(best, k)
        return best

    def satisfied(self, state: WorldState) -> bool:
        if self.yellow not in state.positions:
            return False
        rel = relations(state)
        rest = self._rest(state)
        return rel.in_bowl(self.yellow) is not None and any(
            sorted(t) == sorted(rest) for t in standing_towers(state, rel)
        )

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if self.yellow not in state.positions or not n:
            return 0.0
        rel = relations(state)
        return _cap(((rel.in_bowl(self.yellow) is not None) + self._best_tower(state, rel)) / n, n)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        if step.block == self.yellow:
            return rel.in_bowl(self.yellow) is None
        if rel.in_bowl(step.block) is not None or rel.below(step.block) is None:
            return True
        tower = next((t for t in standing_towers(after, rel) if step.block in t), None)
        return tower is None or self.yellow in tower[: tower.index(step.block)]

    def feasible(self, scene: Scene) -> bool:
        return self.yellow in scene.blocks and len(scene.blocks) >= 2 and bool(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        blocks = ["yellow", *_colors(rng, n_blocks - 1, exclude=("yellow",))]
        return _scene(rng, blocks, _colors(rng, 1 + int(rng.integers(0, 2))))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        prep = _Steps(state)
        prep.clear(self.yellow)
        if relations(prep.state).in_bowl(self.yellow) is None:
            prep.do(PutIn(block=self.yellow, bowl=_nearest_bowls(prep.state, self.yellow)[0]))
        if not prep.ok:
            return None
        rest = self._rest(prep.state)
        towers = (_build_tower(prep.state, list(order)) for order in permutations(rest))
        return _shortest(self, state, ([*prep.steps, *t] if t is not None else None for t in towers))


# --- exact counts per container ---------------------------------------------------------------


class AllButOneInOneBowl(Intention):
    name = "h2-all-but-one-in-one-bowl"
    description = "Put all the blocks but one together in the same bowl, and leave the last one on the table."

    def _outside(self, state: WorldState, rel: Relations) -> list[str]:
        return [b for b in state.blocks if rel.in_bowl(b) is None]

    def satisfied(self, state: WorldState) -> bool:
        n = len(state.blocks)
        if n < 2 or not state.bowls:
            return False
        rel = relations(state)
        out = self._outside(state, rel)
        most = max(len(_contents(rel, w)) for w in state.bowls)
        return len(out) == 1 and on_table(rel, out[0]) and most == n - 1

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if n < 1 or not state.bowls:
            return 0.0
        rel = relations(state)
        most = min(max(len(_contents(rel, w)) for w in state.bowls), n - 1)
        left_out = any(on_table(rel, b) for b in self._outside(state, rel))
        return _cap((most + left_out) / n, n)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        bowl = rel.in_bowl(step.block)
        if bowl is None:
            return rel.below(step.block) is not None  # stacked on the table: neither in nor left out
        mine = len(_contents(rel, bowl))
        return any(len(_contents(rel, w)) >= mine for w in after.bowls if w != bowl)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2 and bool(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 3))
        return _scene(rng, _colors(rng, n_blocks), _colors(rng, 1 if n_blocks == 4 else 1 + int(rng.integers(0, 2))))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)
        bowls = sorted(state.bowls, key=lambda w: -len(_contents(rel, w)))
        keepers = sorted(state.blocks, key=lambda b: (not _alone_on_table(rel, b), rel.in_bowl(b) is not None))

        def candidates() -> Iterator[list[Skill] | None]:
            for target in bowls:
                for out in keepers:
                    plan = _Steps(state)
                    if not on_table(relations(plan.state), out):
                        plan.clear(out)
                        plan.do(park(plan.state, out))
                    for b in top_first(plan.state, [b for b in state.blocks if b != out]):
                        if relations(plan.state).in_bowl(b) != target:
                            plan.do(PutIn(block=b, bowl=target))
                    yield plan.steps if plan.ok else None

        return _first_verified(self, state, (c for c in candidates() if c is not None), limit=40)


class OneInEveryBowl(Intention):
    name = "h2-one-in-every-bowl"
    description = "Put exactly one block in every bowl and leave any extra blocks on the table."

    def satisfied(self, state: WorldState) -> bool:
        if not state.bowls or not state.blocks:
            return False
        rel = relations(state)
        return all(len(_contents(rel, w)) == 1 for w in state.bowls) and all(
            on_table(rel, b) for b in state.blocks if rel.in_bowl(b) is None
        )

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if not n or not state.bowls:
            return 0.0
        rel = relations(state)
        single = sum(len(_contents(rel, w)) == 1 for w in state.bowls)
        extra = sum(on_table(rel, b) for b in state.blocks if rel.in_bowl(b) is None)
        return _cap((single + min(extra, max(0, n - len(state.bowls)))) / n, n)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        bowl = rel.in_bowl(step.block)
        if bowl is not None:
            return len(_contents(rel, bowl)) > 1
        return rel.below(step.block) is not None

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.bowls) <= len(scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        n_bowls = 1 + int(rng.integers(0, 2))
        return _scene(rng, _colors(rng, n_blocks), _colors(rng, n_bowls))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        plan = _Steps(state)
        for _ in range(4 * len(state.blocks) + 4):
            if self.satisfied(plan.state):
                return verified(self, state, plan.steps)
            current = plan.state
            rel = relations(current)
            crowded = [w for w in current.bowls if len(_contents(rel, w)) > 1]
            stacked = [b for b in current.blocks if rel.in_bowl(b) is None and rel.below(b) is not None
                       and is_clear(rel, b)]
            empty = [w for w in current.bowls if not _contents(rel, w)]
            if crowded:
                top = max(_contents(rel, crowded[0]), key=lambda b: current.pos(b)[2])
                plan.do(park(current, top))
            elif stacked:
                plan.do(park(current, stacked[0]))
            elif empty:
                free = [b for b in current.blocks if rel.in_bowl(b) is None and is_clear(rel, b)]
                if not free:
                    return None
                w = empty[0]
                b = min(free, key=lambda b: float(np.hypot(*(current.pos(b)[:2] - current.pos(w)[:2]))))
                plan.do(PutIn(block=b, bowl=w))
            else:
                return None
            if not plan.ok:
                return None
        return None


class OneLeftRestRight(Intention):
    name = "h2-one-left-rest-right"
    description = (
        "Put one block in the bowl furthest to the left and all the other blocks in the bowl "
        "furthest to the right."
    )

    def satisfied(self, state: WorldState) -> bool:
        if len(state.bowls) < 2 or len(state.blocks) < 2:
            return False
        rel = relations(state)
        left, right = _leftmost_bowl(state), _rightmost_bowl(state)
        in_left = _contents(rel, left)
        return len(in_left) == 1 and all(rel.in_bowl(b) == right for b in state.blocks if b not in in_left)

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if len(state.bowls) < 2 or not n:
            return 0.0
        rel = relations(state)
        left, right = _leftmost_bowl(state), _rightmost_bowl(state)
        return _cap((min(len(_contents(rel, left)), 1) + len(_contents(rel, right))) / n, n)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks or len(after.bowls) < 2:
            return False
        rel = relations(after)
        left, right = _leftmost_bowl(after), _rightmost_bowl(after)
        bowl = rel.in_bowl(step.block)
        if bowl == left:
            return len(_contents(rel, left)) > 1
        return bowl != right

    def feasible(self, scene: Scene) -> bool:
        return len(scene.bowls) >= 2 and len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_blocks = 2 + int(rng.integers(0, 2))
        n_bowls = 2 + int(rng.integers(0, 2)) if n_blocks == 2 else 2
        return _scene(rng, _colors(rng, n_blocks), _colors(rng, n_bowls))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)
        left, right = _leftmost_bowl(state), _rightmost_bowl(state)
        in_left = sorted(_contents(rel, left), key=lambda b: state.pos(b)[2])
        if in_left:
            keepers = in_left[:1]
        else:
            lx = state.pos(left)[:2]
            keepers = sorted(state.blocks, key=lambda b: (rel.in_bowl(b) == right, not is_clear(rel, b),
                                                          float(np.hypot(*(state.pos(b)[:2] - lx)))))

        def candidates() -> Iterator[list[Skill]]:
            for keeper in keepers:
                plan = _Steps(state)
                if relations(plan.state).in_bowl(keeper) != left:
                    plan.clear(keeper)
                    plan.do(PutIn(block=keeper, bowl=left))
                for b in top_first(plan.state, [b for b in state.blocks if b != keeper]):
                    if relations(plan.state).in_bowl(b) != right:
                        plan.do(PutIn(block=b, bowl=right))
                if plan.ok:
                    yield plan.steps

        return _first_verified(self, state, candidates(), limit=20)


# --- structures at a place --------------------------------------------------------------------


class SpreadAlongFrontEdge(BlockwiseIntention):
    name = "h2-spread-along-front-edge"
    description = "Spread the blocks out along the front edge of the table, with none of them touching."

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        if not _alone_on_table(rel, block) or state.pos(block)[1] > FRONT_Y:
            return False
        return not any(rel.is_next_to(block, o) for o in state.blocks if o != block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        (x0, x1), _ = TABLE_INNER
        spots = [(float(x), float(y)) for x in np.arange(x0, x1 + 1e-9, 0.02) for y in (-0.75, -0.73, -0.71)]
        return free_spot(state, block, spots, accept=lambda s: self.wanted(s, relations(s), block))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _any_scene(rng)


# --- pairs ------------------------------------------------------------------------------------


class TowersOfTwo(Intention):
    name = "h2-towers-of-two"
    description = "Pair the blocks up into little towers of two blocks each."

    def satisfied(self, state: WorldState) -> bool:
        n = len(state.blocks)
        ts = standing_towers(state, relations(state))
        return n >= 2 and n % 2 == 0 and all(len(t) == 2 for t in ts) and sum(map(len, ts)) == n

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        pairs = sum(len(t) == 2 for t in standing_towers(state, relations(state)))
        return _cap(2 * pairs / n, n) if n else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        tower = next((t for t in standing_towers(after, rel) if step.block in t), None)
        return tower is None or len(tower) != 2

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2 and len(scene.blocks) % 2 == 0

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _any_scene(rng, 2 if rng.random() < 0.5 else 4)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        plan = _Steps(state)
        for _ in range(4 * len(state.blocks) + 4):
            current = plan.state
            if self.satisfied(current):
                return verified(self, state, plan.steps)
            rel = relations(current)
            ts = standing_towers(current, rel)
            standing = {b for t in ts for b in t}
            loose = [b for b in current.blocks if b not in standing and is_clear(rel, b)]
            tall = [t for t in ts if len(t) > 2]
            singles = [t[0] for t in ts if len(t) == 1]
            if loose:
                plan.do(park(current, loose[0]))
            elif tall:
                plan.do(park(current, tall[0][-1]))
            elif len(singles) >= 2:
                a, b = min(combinations(singles, 2),
                           key=lambda p: float(np.hypot(*(current.pos(p[0])[:2] - current.pos(p[1])[:2]))))
                plan.do(PutOn(block=b, target=a))
            else:
                return None
            if not plan.ok:
                return None
        return None


class WarmBesideCool(BlockwiseIntention):
    name = "h2-warm-beside-cool"
    description = "Put each warm-coloured block on the table right next to a cool-coloured one."

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        if not is_warm(block):
            return True
        return on_table(rel, block) and any(
            on_table(rel, c) and rel.is_next_to(block, c) for c in state.blocks if not is_warm(c)
        )

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        here = state.pos(block)[:2]
        cools = sorted((c for c in state.blocks if not is_warm(c) and on_table(rel, c)),
                       key=lambda c: float(np.hypot(*(state.pos(c)[:2] - here))))
        for c in cools:
            for side in ("nearest", "left", "right", "front", "behind"):
                step = PutNextTo(block=block, target=c, side=side)  # type: ignore[arg-type]
                after, failure = apply_skill(state, step)
                if failure is None and self.wanted(after, relations(after), block):
                    return step
        if not cools:  # every cool block is in a bowl or on a block: set one down first
            for c in (c for c in state.blocks if not is_warm(c) and is_clear(rel, c)):
                if step := self.park(state, c):
                    return step
        return None

    def feasible(self, scene: Scene) -> bool:
        return bool(_warm(scene)) and bool(_cool(scene))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm = 1 + int(rng.integers(0, 2))
        n_cool = 1 + int(rng.integers(0, 2))
        blocks = _colors(rng, n_warm, WARM_COLORS) + _colors(rng, n_cool, COOL_COLORS)
        n_bowls = int(rng.integers(max(0, 3 - len(blocks)), min(2, 5 - len(blocks)) + 1))
        return _scene(rng, blocks, _colors(rng, n_bowls))


class WarmCoolPairsInBowls(Intention):
    name = "h2-warm-cool-pairs-in-bowls"
    description = "Put the blocks into the bowls in pairs, one warm-coloured and one cool-coloured block in each bowl used."

    @staticmethod
    def _pair(bowl_contents: list[str]) -> bool:
        return len(bowl_contents) == 2 and is_warm(bowl_contents[0]) != is_warm(bowl_contents[1])

    def satisfied(self, state: WorldState) -> bool:
        if not state.blocks:
            return False
        rel = relations(state)
        if any(rel.in_bowl(b) is None for b in state.blocks):
            return False
        return all(self._pair(_contents(rel, w)) for w in state.bowls if _contents(rel, w))

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if not n:
            return 0.0
        rel = relations(state)
        paired = sum(2 for w in state.bowls if self._pair(_contents(rel, w)))
        return _cap(paired / n, n)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        rel = relations(after)
        bowl = rel.in_bowl(step.block)
        if bowl is None:
            return True
        inside = _contents(rel, bowl)
        return len(inside) > 2 or (len(inside) == 2 and not self._pair(inside))

    def feasible(self, scene: Scene) -> bool:
        w, c = len(_warm(scene)), len(_cool(scene))
        return w == c >= 1 and len(scene.bowls) >= w

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        # One warm and one cool block (two pairs would need two bowls: six objects, too many).
        blocks = _colors(rng, 1, WARM_COLORS) + _colors(rng, 1, COOL_COLORS)
        return _scene(rng, blocks, _colors(rng, 1 + int(rng.integers(0, 3))))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        plan = _Steps(state)
        for _ in range(4 * len(state.blocks) + 4):
            current = plan.state
            if self.satisfied(current):
                return verified(self, state, plan.steps)
            rel = relations(current)
            inside = {w: _contents(rel, w) for w in current.bowls}
            bad = [w for w, c in inside.items()
                   if len(c) > 2 or sum(map(is_warm, c)) > 1 or sum(not is_warm(b) for b in c) > 1]
            outside = [b for b in current.blocks if rel.in_bowl(b) is None]
            loose = [b for b in outside if is_clear(rel, b)]
            half = [w for w, c in inside.items() if len(c) == 1]
            empty = [w for w, c in inside.items() if not c]
            if bad:
                top = max(inside[bad[0]], key=lambda b: current.pos(b)[2])
                plan.do(park(current, top))
            elif half and (mates := [b for b in loose if is_warm(b) != is_warm(inside[half[0]][0])]):
                plan.do(PutIn(block=mates[0], bowl=half[0]))
            elif loose and empty:
                plan.do(PutIn(block=loose[0], bowl=empty[0]))
            else:  # blocks left out but none can be put in
                return None
            if not plan.ok:
                return None
        return None


# --- two clauses ------------------------------------------------------------------------------


class WarmInBowlsCoolRow(Intention):
    name = "h2-warm-in-bowls-cool-row"
    description = (
        "Put the warm-coloured blocks in bowls and line the cool-coloured blocks up side by side "
        "in a row on the table."
    )

    def satisfied(self, state: WorldState) -> bool:
        rel = relations(state)
        warm, cool = _warm(state), _cool(state)
        return (bool(warm) and bool(cool) and all(rel.in_bowl(b) is not None for b in warm)
                and _line(state, rel, cool))

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if not n:
            return 0.0
        rel = relations(state)
        warm_ok = sum(rel.in_bowl(b) is not None for b in _warm(state))
        row = _largest(_cool(state), lambda c: _line(state, rel, c))
        return _cap((warm_ok + row) / n, n)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if step.block not in after.blocks:
            return False
        if is_warm(step.block):
            return relations(after).in_bowl(step.block) is None
        return _row_step_away(after, step.block, _cool(after))

    def feasible(self, scene: Scene) -> bool:
        return bool(_warm(scene)) and bool(_cool(scene)) and bool(scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        n_warm = 1 + int(rng.integers(0, 2))
        n_cool = 1 + int(rng.integers(0, 2)) if n_warm == 1 else 2
        blocks = _colors(rng, n_warm, WARM_COLORS) + _colors(rng, n_cool, COOL_COLORS)
        n_bowls = 1 if len(blocks) == 4 else 1 + int(rng.integers(0, 2))
        return _scene(rng, blocks, _colors(rng, n_bowls))

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        prep = _Steps(state)
        for w in top_first(state, _warm(state)):
            if relations(prep.state).in_bowl(w) is None:
                prep.clear(w)
                prep.do(PutIn(block=w, bowl=_nearest_bowls(prep.state, w)[0]))
        if not prep.ok:
            return None
        cool = _cool(state)
        orders = [list(p) for p in permutations(top_first(prep.state, cool))]
        rows = _row_candidates(prep.state, orders, _Row.ys)
        if len(cool) == 1 and not on_table(relations(prep.state), cool[0]):  # a row of one: on the table
            rows = iter([[s] for s in [park(prep.state, cool[0])] if s is not None])
        return _first_verified(self, state, ([*prep.steps, *r] for r in rows), limit=2000) or (
            verified(self, state, prep.steps)
        )


HELDOUT2: tuple[type[Intention], ...] = (
    RedInFrontOfLeftBowl,
    BlueOnAnotherBlock,
    GreenInRightBowl,
    PurpleInBowlLeaveRest,
    CyanToFrontRightCornerLeaveRest,
    AlphabeticalTower,
    WarmUnderCoolTower,
    OrangeAtBottomTower,
    TowerInMiddle,
    AlternatingRow,
    RowAlongBackEdge,
    InFrontOfOwnBowl,
    IntoAnotherBlocksBowl,
    OwnBowlElseRightHalf,
    AllButGreenInBowls,
    AllButYellowTowerYellowInBowl,
    AllButOneInOneBowl,
    OneInEveryBowl,
    OneLeftRestRight,
    SpreadAlongFrontEdge,
    TowersOfTwo,
    WarmBesideCool,
    WarmCoolPairsInBowls,
    WarmInBowlsCoolRow,
)


def heldout2_intentions() -> list[Intention]:
    """One fresh instance of every intention of the suite, in a fixed order."""
    return [cls() for cls in HELDOUT2]
