"""A blind, held-out suite of intentions for testing how far learners generalise.

These intentions were written without looking at what any learner can represent: they are
things a person could plausibly want from a tabletop robot (relations between objects,
orderings, table regions, counts, exceptions, "leave the rest alone", two-clause rules).
Several of them lie outside the Bayesian learners' hypothesis grammar on purpose. Nothing here
imports from ``activeintent.learners``; only the world model and the intention helpers are used.

Conventions (see ``world/skills.py``): x grows from left to right, y from the front edge of the
table (y = -0.8, nearest the person) to the back edge (y = -0.2). "In front of" means smaller y.

"Stays where it is" can only be judged on the final state, which carries no memory of the
start, so there it means: still standing alone on the table (not in a bowl, not stacked, nothing
on top). Picking such a block up at all is what ``step_moves_away`` reports, so a person
watching the robot stops it as soon as it touches a block that should stay.

The benchmark draws test scenes from one distribution for every intention (2-4 blocks,
1-2 bowls); each intention here is feasible on a fair share of those scenes.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.intentions.blockwise import BlockwiseIntention
from activeintent.intentions.placement import (
    LINE_TOL,
    free_spot,
    grid,
    is_clear,
    is_warm,
    nearest_first,
    on_table,
    standing_towers,
    top_first,
    towers,
    verified,
)
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_RADIUS,
    COLORS,
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
    sample_scene,
)
from activeintent.world.scene import MIN_SPACING, ROW_PITCH, color_of

# Blocks are put at least this far inside the 60 cm square, so that no block hangs over it.
EDGE_INSET = 0.02
INNER_X = (BOUNDS[0][0] + EDGE_INSET, BOUNDS[0][1] - EDGE_INSET)
INNER_Y = (BOUNDS[1][0] + EDGE_INSET, BOUNDS[1][1] - EDGE_INSET)
CENTRE = np.array([0.0, -0.5])
FRONT_BAND_Y = -0.70  # "along the front edge": within 10 cm of it
BACK_HALF_Y = -0.5
CENTRE_RADIUS = 0.15  # "in the middle of the table": within 15 cm of its centre
# "In front of a bowl": the block's offset from the bowl points forward within about 45°;
# the slack absorbs the few millimetres by which the simulator settles a block.
CONE_SLACK = 0.02
FRONT_CORNERS = ("bottom left corner", "bottom right corner")
EPS = 1e-9
FINGER_ROOM = 0.01


def _lightness(color: str) -> float:
    """Relative luminance of a palette colour (sRGB, as a person perceives light vs dark)."""

    def linear(c: float) -> float:
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = (linear(c) for c in COLORS[color])
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def _inside_table(xy: tuple[float, float]) -> bool:
    return INNER_X[0] <= xy[0] <= INNER_X[1] and INNER_Y[0] <= xy[1] <= INNER_Y[1]


def _flat(rel: Relations, block: str) -> bool:
    """Standing alone on the table: not in a bowl, not on a block, nothing on top."""
    return on_table(rel, block) and is_clear(rel, block)


def _bowl_counts(state: WorldState, rel: Relations) -> dict[str, int]:
    counts = dict.fromkeys(state.bowls, 0)
    for _, bowl in rel.inside:
        counts[bowl] += 1
    return counts


def _own_bowl(block: str) -> str:
    return f"{color_of(block)} bowl"


def _distance(state: WorldState, a: str, b: str) -> float:
    return float(np.hypot(*(state.pos(a)[:2] - state.pos(b)[:2])))


def _moved(before: WorldState, after: WorldState) -> bool:
    return before.positions != after.positions


def _run(state: WorldState, step: Skill | None) -> WorldState | None:
    """The predicted state after ``step``, None if there is no step or it fails."""
    if step is None:
        return None
    after, failure = apply_skill(state, step)
    return None if failure is not None else after


def _roomy(state: WorldState, block: str) -> bool:
    """Does ``block`` keep a finger's width from its neighbours on the table?

    The world model lets blocks almost touch; the robot's fingers need about a centimetre,
    so spots the robot chooses freely keep that much room.
    """
    here = state.pos(block)
    for other in state.names:
        if other == block:
            continue
        if state.kind(other) == "bowl":
            room = BOWL_RADIUS + BLOCK_SIZE / 2
        elif abs(state.pos(other)[2] - here[2]) <= BLOCK_SIZE / 2:  # a block on the same level
            room = BLOCK_SIZE
        else:
            continue
        if float(np.hypot(*(state.pos(other)[:2] - here[:2]))) < room + FINGER_ROOM:
            return False
    return True


def _put_free(state: WorldState, block: str, spots, accept=None) -> PutAt | None:
    """The first of ``spots`` where ``block`` can go with room around it (and ``accept`` holds)."""
    return free_spot(state, block, spots,
                     accept=lambda after: _roomy(after, block) and (accept is None or accept(after)))


def _park(state: WorldState, block: str) -> PutAt | None:
    """Put ``block`` on a free table spot near where it is (to clear a stack or a bowl)."""
    spots = nearest_first(grid(INNER_X, INNER_Y, step=0.05), state.pos(block))
    return _put_free(state, block, spots, accept=lambda after: _flat(relations(after), block))


def _smooth(intention: Intention, state: WorldState, steps: list[Skill]) -> list[Skill] | None:
    """``steps`` if they satisfy ``intention`` and no step on the way looks wrong to a watcher."""
    if verified(intention, state, steps) is None:
        return None
    before = state
    for step in steps:
        after = _run(before, step)
        if after is None or intention.step_moves_away(before, after, step):
            return None
        before = after
    return steps


def benchmark_like_scene(rng: np.random.Generator) -> Scene:
    """2-4 blocks and 1-2 bowls, bowls matching block colours half of the time (3-5 objects)."""
    while True:
        n_blocks, n_bowls = int(rng.integers(2, 5)), int(rng.integers(1, 3))
        if n_blocks + n_bowls <= 5:  # Intention.sample_scene promises 3-5 objects
            break
    matching = True if rng.random() < 0.5 else None
    return sample_scene(rng, n_blocks=n_blocks, n_bowls=n_bowls, matching=matching)


class _FromBenchmarkScenes:
    """Samples scenes like the benchmark's, keeping the first one the intention is feasible in."""

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        for _ in range(2000):
            scene = benchmark_like_scene(rng)
            if self.feasible(scene):
                return scene
        raise ValueError(f"no feasible scene found for {getattr(self, 'name', '?')!r}")


# ---- relations -------------------------------------------------------------------------------


class InFrontOfABowl(_FromBenchmarkScenes, BlockwiseIntention):
    name = "in-front-of-a-bowl"
    description = "Put every block on the table just in front of one of the bowls."

    @staticmethod
    def in_front_of(state: WorldState, block: str, target: str) -> bool:
        dx, dy = state.pos(block)[:2] - state.pos(target)[:2]
        return dy < 0 and abs(dx) <= -dy + CONE_SLACK

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return on_table(rel, block) and any(
            rel.is_next_to(block, bowl) and self.in_front_of(state, block, bowl) for bowl in state.bowls
        )

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        def ok(after: WorldState) -> bool:
            return self.wanted(after, relations(after), block)

        # Straight in front first, then fanning out: near the front edge only the slanted
        # spots stay on the table.
        angles = np.radians([0, 12, -12, 24, -24, 33, -33, 40, -40])
        for bowl in sorted(state.bowls, key=lambda w: _distance(state, block, w)):
            centre = state.pos(bowl)[:2]
            ring = [
                (float(centre[0] + r * np.sin(a)), float(centre[1] - r * np.cos(a)))
                for a in angles
                for r in (0.097, 0.108, 0.12)
            ]
            if step := _put_free(state, block, [p for p in ring if _inside_table(p)], accept=ok):
                return step
        return None

    def feasible(self, scene: Scene) -> bool:
        # Two blocks always fit in front of a bowl, even one standing at the front edge.
        return 1 <= len(scene.blocks) <= 2 * len(scene.bowls)


class WarmLeftOfCool(_FromBenchmarkScenes, BlockwiseIntention):
    name = "warm-left-of-cool"
    description = (
        "Keep all the blocks on the table, with every warm-coloured block further left than "
        "every cool-coloured block."
    )

    @staticmethod
    def wrong_pairs(state: WorldState, block: str) -> int:
        """How many blocks of the other colour class are on the wrong side of ``block``."""
        x = state.pos(block)[0]
        if is_warm(block):
            return sum(1 for o in state.blocks if not is_warm(o) and state.pos(o)[0] <= x)
        return sum(1 for o in state.blocks if is_warm(o) and state.pos(o)[0] >= x)

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return on_table(rel, block) and self.wrong_pairs(state, block) == 0

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        return None  # plan() below moves blocks across a chosen dividing line instead

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        if not on_table(relations(after), block):
            return True
        return self.wrong_pairs(after, block) > self.wrong_pairs(before, block)

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if is_warm(b)]
        return bool(warm) and len(warm) < len(scene.blocks)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        rel = relations(state)

        def fits(block: str, split: float) -> bool:
            x = state.pos(block)[0]
            return on_table(rel, block) and (x < split - 0.02 if is_warm(block) else x > split + 0.02)

        # A dividing line that leaves as many blocks as possible where they are (then central).
        splits = [round(float(s), 3) for s in np.arange(-0.2, 0.2001, 0.02)]
        splits.sort(key=lambda s: (sum(not fits(b, s) for b in state.blocks), abs(s)))
        for split in splits[:6]:
            steps: list[Skill] = []
            current = state
            for block in top_first(state, [b for b in state.blocks if not fits(b, split)]):
                side = (INNER_X[0], split - 0.04) if is_warm(block) else (split + 0.04, INNER_X[1])
                spots = nearest_first(grid(side, INNER_Y, step=0.04), current.pos(block))
                step = _put_free(current, block, spots, accept=lambda s, b=block: on_table(relations(s), b))
                current = _run(current, step)
                if current is None:
                    break
                steps.append(step)
            else:
                if found := verified(self, state, steps):
                    return found
        return None


# ---- orderings -------------------------------------------------------------------------------


def _line_ok(state: WorldState, rel: Relations, members, axis: int, rank) -> bool:
    """``members`` form one straight line on the table along ``axis`` (0: left-right row,
    1: front-back column), neighbours next to each other, ``rank`` never decreasing along it."""
    if not members or not all(_flat(rel, b) for b in members):
        return False
    across = [state.pos(b)[1 - axis] for b in members]
    if max(across) - min(across) > LINE_TOL:
        return False
    ordered = sorted(members, key=lambda b: state.pos(b)[axis])
    for a, b in zip(ordered, ordered[1:], strict=False):
        if state.pos(b)[axis] - state.pos(a)[axis] < MIN_SPACING or not rel.is_next_to(a, b):
            return False
        if rank(b) < rank(a):
            return False
    return True


def _longest_line(state: WorldState, rel: Relations, members, axis: int, rank) -> int:
    """Size of the largest subset of ``members`` that already forms a valid line."""
    flat = [b for b in members if _flat(rel, b)]
    for size in range(len(flat), 1, -1):
        if any(_line_ok(state, rel, combo, axis, rank) for combo in combinations(flat, size)):
            return size
    return 1 if flat else 0


def _line_misstep(after: WorldState, block: str, members, axis: int, rank) -> bool:
    """Was ``block`` just set where no line of ``members`` in the wanted order can use it?"""
    rel = relations(after)
    if not _flat(rel, block):
        return True
    neighbours = [o for o in members if o != block and _flat(rel, o) and rel.is_next_to(block, o)]
    if not neighbours:
        return False  # set down alone: nothing to judge yet
    across = after.pos(block)[1 - axis]
    in_line = [o for o in neighbours if abs(after.pos(o)[1 - axis] - across) <= LINE_TOL]
    if not in_line:
        return True  # beside blocks but in line with none of them
    along = after.pos(block)[axis]
    return any((rank(o) - rank(block)) * (after.pos(o)[axis] - along) < 0 for o in in_line)


def _plan_line(state: WorldState, members: list[str], axis: int, rank, accept) -> list[Skill] | None:
    """Steps that lay ``members`` out as a line along ``axis`` in ``rank`` order.

    A piece of the line that already stands is kept if the other blocks can go at its ends;
    else the blocks are chained onto the first (or the last) one where it stands; failing that
    they are put at the points of a free line, the lines nearest the table centre first.
    ``accept(steps)`` returns the steps when the world model says they reach the goal.
    """
    if not members:
        return accept([])
    order = sorted(members, key=lambda b: (rank(b), state.pos(b)[axis]))
    forward, backward = ("right", "left") if axis == 0 else ("behind", "front")
    rel = relations(state)
    # A piece of the line that already stands is kept when the others fit at its two ends.
    for size in range(len(members) - 1, 1, -1):
        for piece in combinations(members, size):
            if not _line_ok(state, rel, piece, axis, rank):
                continue
            piece = sorted(piece, key=lambda b: state.pos(b)[axis])
            low, high = rank(piece[0]), rank(piece[-1])
            rest = [b for b in order if b not in piece]
            before = [b for b in rest if rank(b) <= low]
            after = [b for b in rest if b not in before and rank(b) >= high]
            if len(before) + len(after) < len(rest):
                continue
            extend: list[Skill] = []
            for prev, b in zip([piece[0], *before[::-1]], before[::-1], strict=False):
                extend.append(PutNextTo(block=b, target=prev, side=backward))
            for prev, b in zip([piece[-1], *after], after, strict=False):
                extend.append(PutNextTo(block=b, target=prev, side=forward))
            if found := accept(extend):
                return found
    if _flat(rel, order[0]):
        chain: list[Skill] = [
            PutNextTo(block=b, target=prev, side=forward) for prev, b in zip(order, order[1:], strict=False)
        ]
        if found := accept(chain):
            return found
    if _flat(rel, order[-1]):
        reverse = order[::-1]
        chain = [PutNextTo(block=b, target=prev, side=backward) for prev, b in zip(reverse, reverse[1:], strict=False)]
        if found := accept(chain):
            return found
    length = ROW_PITCH * (len(order) - 1)
    along = INNER_X if axis == 0 else INNER_Y
    across = INNER_Y if axis == 0 else INNER_X
    starts = grid((along[0], along[1] - length), across, step=0.04)
    if axis == 1:
        starts = [(a, s) for s, a in starts]  # grid gives (along, across); columns want (x, y)
    centre_start = CENTRE - (np.array([length / 2, 0.0]) if axis == 0 else np.array([0.0, length / 2]))
    for start in nearest_first(starts, centre_start)[:60]:
        placements: list[Skill] = []
        for i, b in enumerate(order):
            point = list(start)
            point[axis] += i * ROW_PITCH
            placements.append(PutAt(block=b, position=(float(point[0]), float(point[1]))))
        if found := accept(placements):
            return found
    return None


class _OrderedLine(_FromBenchmarkScenes, Intention):
    """Every block in one line (``axis``: 0 a left-right row, 1 a front-back column), ordered
    by ``rank`` from left to right (from front to back)."""

    axis = 0

    def rank(self, block: str) -> float:
        raise NotImplementedError

    def satisfied(self, state: WorldState) -> bool:
        return _line_ok(state, relations(state), state.blocks, self.axis, self.rank)

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        return _longest_line(state, relations(state), state.blocks, self.axis, self.rank) / n if n else 0.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        if step.block not in after.blocks or not _moved(before, after):
            return False
        return _line_misstep(after, step.block, after.blocks, self.axis, self.rank)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        # Blocks in bowls or stacks are first set down on the table, tops first.
        steps: list[Skill] = []
        current = state
        for b in top_first(state, state.blocks):
            if not _flat(relations(current), b):
                step = _park(current, b)
                current = _run(current, step)
                if current is None:
                    return None
                steps.append(step)
        # Prefer a layout whose every step visibly builds the line; else any that works.
        for check in (_smooth, verified):
            found = _plan_line(current, current.blocks, self.axis, self.rank,
                               lambda more, check=check: check(self, state, steps + more))
            if found is not None:
                return found
        return None


class RowDarkToLight(_OrderedLine):
    name = "row-dark-to-light"
    description = (
        "Line the blocks up in one left-to-right row on the table, from the darkest colour on "
        "the left to the lightest on the right."
    )
    axis = 0

    def rank(self, block: str) -> float:
        return _lightness(color_of(block))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2


class ColumnWarmInFront(_OrderedLine):
    name = "column-warm-in-front"
    description = (
        "Line the blocks up in one front-to-back column on the table, with the warm-coloured "
        "blocks in front and the cool-coloured blocks behind them."
    )
    axis = 1

    def rank(self, block: str) -> float:
        return 0.0 if is_warm(block) else 1.0

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if is_warm(b)]
        return bool(warm) and len(warm) < len(scene.blocks)


class TowerWarmUnderCool(_FromBenchmarkScenes, Intention):
    name = "tower-warm-under-cool"
    description = (
        "Stack all the blocks into one tower, with the warm-coloured blocks at the bottom and the "
        "cool-coloured blocks on top of them."
    )

    @staticmethod
    def good_height(state: WorldState, tower: list[str]) -> int:
        """How many blocks from the bottom of ``tower`` can stay in the final tower.

        A cool block may only stand above the warm ones once every warm block is below it.
        """
        warm_total = sum(1 for b in state.blocks if is_warm(b))
        warm_seen = 0
        for i, b in enumerate(tower):
            if is_warm(b):
                if warm_seen < i:  # a warm block above a cool one
                    return i
                warm_seen += 1
            elif warm_seen < warm_total:
                return i
        return len(tower)

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if not n:
            return 0.0
        return max((self.good_height(state, t) for t in standing_towers(state, relations(state))), default=0) / n

    def satisfied(self, state: WorldState) -> bool:
        return bool(state.blocks) and self.score(state) >= 1.0 - EPS

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        rel = relations(after)
        below = rel.below(block)
        if below is None:
            return True  # building a tower only ever puts blocks on blocks
        tower = next((t for t in standing_towers(after, rel) if block in t), None)
        return tower is None or self.good_height(after, tower) <= tower.index(block)

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if is_warm(b)]
        return bool(warm) and len(warm) < len(scene.blocks)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        steps: list[Skill] = []
        current = state
        # Keep the best-started tower; everything else is taken down first (tops first).
        keep = max(standing_towers(state, relations(state)), key=lambda t: self.good_height(state, t), default=[])
        keep = keep[: self.good_height(state, keep)]
        for b in top_first(state, state.blocks):
            if b in keep or _flat(relations(current), b):
                continue
            step = _park(current, b)
            current = _run(current, step)
            if current is None:
                return None
            steps.append(step)
        if not keep:
            warm = [b for b in current.blocks if is_warm(b)]
            keep = [min(warm, key=lambda b: float(np.hypot(*(current.pos(b)[:2] - CENTRE))))]
        rest = [b for b in current.blocks if b not in keep]
        order = sorted(rest, key=lambda b: not is_warm(b))  # warm ones first
        top = keep[-1]
        for b in order:
            steps.append(PutOn(block=b, target=top))
            top = b
        return verified(self, state, steps)


# ---- table regions -------------------------------------------------------------------------


class _RegionIntention(_FromBenchmarkScenes, BlockwiseIntention):
    """Every block on the table inside a region; ``spots`` are where the robot puts them."""

    def inside(self, state: WorldState, rel: Relations, block: str) -> bool:
        raise NotImplementedError

    def spots(self, state: WorldState, block: str) -> list:
        raise NotImplementedError

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        return on_table(rel, block) and self.inside(state, rel, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        return _put_free(state, block, self.spots(state, block),
                         accept=lambda after: self.wanted(after, relations(after), block))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1


class AlongTheFrontEdge(_RegionIntention):
    name = "along-the-front-edge"
    description = "Put all the blocks on the table along the front edge, the side nearest to me."

    def inside(self, state: WorldState, rel: Relations, block: str) -> bool:
        return state.pos(block)[1] <= FRONT_BAND_Y

    def spots(self, state: WorldState, block: str) -> list:
        # 2 cm inside the band's limit: the simulator may settle a block by a few millimetres.
        band = grid(INNER_X, (INNER_Y[0], FRONT_BAND_Y - 0.02), step=0.045)
        return nearest_first(band, state.pos(block))


class BackHalf(_RegionIntention):
    name = "back-half"
    description = "Move all the blocks onto the back half of the table, away from me."

    def inside(self, state: WorldState, rel: Relations, block: str) -> bool:
        return state.pos(block)[1] > BACK_HALF_Y

    def spots(self, state: WorldState, block: str) -> list:
        return nearest_first(grid(INNER_X, (BACK_HALF_Y + 0.03, INNER_Y[1]), step=0.045), state.pos(block))


class FrontCorners(_RegionIntention):
    name = "front-corners"
    description = "Put every block on the table in one of the two front corners of the table."

    def inside(self, state: WorldState, rel: Relations, block: str) -> bool:
        return rel.table_position[block] in FRONT_CORNERS

    def spots(self, state: WorldState, block: str) -> list:
        here = state.pos(block)[:2]
        out: list[tuple[float, float]] = []
        # The corner nearer to the block first; 2 cm inside the 20 cm corner cell.
        for xs in sorted([(INNER_X[0], -0.12), (0.12, INNER_X[1])], key=lambda r: abs(sum(r) / 2 - here[0])):
            cell = grid(xs, (INNER_Y[0], -0.62), step=0.035)
            out += nearest_first(cell, np.array([sum(xs) / 2, -0.72]))
        return out


class GatheredInTheMiddle(_FromBenchmarkScenes, Intention):
    name = "gathered-in-the-middle"
    description = (
        "Gather all the blocks on the table into one tight group in the middle of the table, "
        "each block right next to another."
    )

    @staticmethod
    def central(state: WorldState, rel: Relations, block: str) -> bool:
        return on_table(rel, block) and float(np.hypot(*(state.pos(block)[:2] - CENTRE))) <= CENTRE_RADIUS

    def groups(self, state: WorldState, rel: Relations) -> list[set[str]]:
        """Connected groups of central blocks (next to each other), largest first."""
        left = [b for b in state.blocks if self.central(state, rel, b)]
        out: list[set[str]] = []
        while left:
            group, todo = {left[0]}, [left[0]]
            while todo:
                a = todo.pop()
                for o in left:
                    if o not in group and rel.is_next_to(a, o):
                        group.add(o)
                        todo.append(o)
            out.append(group)
            left = [b for b in left if b not in group]
        return sorted(out, key=len, reverse=True)

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        groups = self.groups(state, relations(state))
        return len(groups[0]) / n if n and groups else 0.0

    def satisfied(self, state: WorldState) -> bool:
        return bool(state.blocks) and self.score(state) >= 1.0 - EPS

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        rel = relations(after)
        if not self.central(after, rel, block):
            return True
        others = [o for o in after.blocks if o != block and self.central(after, rel, o)]
        return bool(others) and not any(rel.is_next_to(block, o) for o in others)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        groups = self.groups(state, relations(state))
        near_centre = nearest_first(grid((-0.12, 0.12), (-0.62, -0.38), step=0.03), CENTRE)
        # Grow the group already in the middle; if it is hemmed in by bowls, start a new one
        # from the free spots nearest the centre.
        if groups and (found := self._gather(state, list(groups[0]), None, near_centre)):
            return found
        for first_spot in near_centre[:40]:
            if found := self._gather(state, [], first_spot, near_centre):
                return found
        return None

    def _gather(self, state: WorldState, group: list[str], first_spot, near_centre) -> list[Skill] | None:
        """Steps that bring every block not in ``group`` next to it (an empty ``group`` is
        started by putting the block nearest the centre at ``first_spot``)."""
        steps: list[Skill] = []
        current = state
        rest = top_first(state, [b for b in state.blocks if b not in group])
        if not group:
            rest.sort(key=lambda b: (-state.pos(b)[2], float(np.hypot(*(state.pos(b)[:2] - CENTRE)))))
        for b in rest:
            if not group:
                step = _put_free(current, b, [first_spot], accept=lambda s, b=b: self.central(s, relations(s), b))
            else:
                step = self._join(current, b, group, near_centre)
            current = _run(current, step)
            if current is None:
                return None
            steps.append(step)
            group = [*group, b]
        return verified(self, state, steps)

    def _join(self, state: WorldState, block: str, group: list[str], near_centre) -> Skill | None:
        """A step that sets ``block`` down in the middle, touching a block of ``group``."""

        def joins(after: WorldState) -> bool:
            rel = relations(after)
            return self.central(after, rel, block) and any(rel.is_next_to(block, o) for o in group)

        by_centre = sorted(group, key=lambda o: float(np.hypot(*(state.pos(o)[:2] - CENTRE))))
        for target in by_centre:
            for side in ("left", "right", "front", "behind"):
                step = PutNextTo(block=block, target=target, side=side)
                after = _run(state, step)
                if after is not None and joins(after):
                    return step
        return _put_free(state, block, near_centre, accept=joins)


# ---- counts, exceptions, leaving the rest alone ------------------------------------------------


class TwoOrMoreInEveryBowl(_FromBenchmarkScenes, Intention):
    name = "two-or-more-in-every-bowl"
    description = "Make sure every bowl ends up with at least two blocks in it."

    def score(self, state: WorldState) -> float:
        counts = _bowl_counts(state, relations(state))
        return sum(min(c, 2) for c in counts.values()) / (2 * len(counts)) if counts else 0.0

    def satisfied(self, state: WorldState) -> bool:
        counts = _bowl_counts(state, relations(state))
        return bool(counts) and all(c >= 2 for c in counts.values())

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        bowl = relations(after).in_bowl(block)
        if bowl is None:
            return True
        # Topping up a bowl that already had two while another one still lacks blocks.
        counts = _bowl_counts(before, relations(before))
        return counts[bowl] >= 2 and any(c < 2 for c in counts.values())

    def feasible(self, scene: Scene) -> bool:
        return bool(scene.bowls) and len(scene.blocks) >= 2 * len(scene.bowls)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.bowls:
            return None
        steps: list[Skill] = []
        current = state
        for _ in range(2 * len(state.bowls)):
            rel = relations(current)
            counts = _bowl_counts(current, rel)
            short = [w for w in current.bowls if counts[w] < 2]
            if not short:
                return verified(self, state, steps)
            bowl = short[0]
            # Blocks not in a bowl first, then spare blocks from bowls holding more than two.
            spare = [b for b in current.blocks if is_clear(rel, b) and (
                rel.in_bowl(b) is None or (rel.in_bowl(b) != bowl and counts[rel.in_bowl(b)] > 2))]
            if not spare:
                return None
            block = min(spare, key=lambda b: (rel.in_bowl(b) is not None, _distance(current, b, bowl)))
            step = PutIn(block=block, bowl=bowl)
            current = _run(current, step)
            if current is None:
                return None
            steps.append(step)
        return verified(self, state, steps)


class OneInEachBowlRestStay(_FromBenchmarkScenes, Intention):
    name = "one-in-each-bowl-rest-stay"
    description = (
        "Put exactly one block in each bowl and leave all the other blocks where they are on "
        "the table."
    )

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if not n or not state.bowls:
            return 0.0
        rel = relations(state)
        filled = sum(min(c, 1) for c in _bowl_counts(state, rel).values())
        resting = sum(1 for b in state.blocks if rel.in_bowl(b) is None and _flat(rel, b))
        return (filled + min(resting, max(0, n - len(state.bowls)))) / n

    def satisfied(self, state: WorldState) -> bool:
        rel = relations(state)
        return (
            bool(state.bowls)
            and all(c == 1 for c in _bowl_counts(state, rel).values())
            and all(rel.in_bowl(b) is not None or _flat(rel, b) for b in state.blocks)
        )

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        rel = relations(after)
        bowl = rel.in_bowl(block)
        # Moving a block anywhere but alone into a bowl disturbs one that should stay.
        return bowl is None or _bowl_counts(after, rel)[bowl] > 1

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.bowls) <= len(scene.blocks)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.bowls or len(state.blocks) < len(state.bowls):
            return None
        if self.satisfied(state):
            return []
        steps: list[Skill] = []
        current = state
        # Untidy starts: extra blocks in bowls and stacked blocks are set down first.
        for b in top_first(state, state.blocks):
            rel = relations(current)
            bowl = rel.in_bowl(b)
            crowded = bowl is not None and _bowl_counts(current, rel)[bowl] > 1
            if (bowl is None and not _flat(rel, b)) or (crowded and is_clear(rel, b)):
                step = _park(current, b)
                current = _run(current, step)
                if current is None:
                    return None
                steps.append(step)
        for bowl in current.bowls:
            rel = relations(current)
            if _bowl_counts(current, rel)[bowl]:
                continue
            free = [b for b in current.blocks if rel.in_bowl(b) is None and _flat(rel, b)]
            if not free:
                return None
            block = min(free, key=lambda b: _distance(current, b, bowl))
            step = PutIn(block=block, bowl=bowl)
            current = _run(current, step)
            if current is None:
                return None
            steps.append(step)
        return verified(self, state, steps)


class MatchOrStay(_FromBenchmarkScenes, BlockwiseIntention):
    name = "match-or-stay"
    description = (
        "Put each block in the bowl of its own colour, and leave any block that has no such bowl "
        "where it is."
    )

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        if _own_bowl(block) in state.positions:
            return rel.in_bowl(block) == _own_bowl(block)
        return _flat(rel, block)

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        if _own_bowl(block) in state.positions:
            return PutIn(block=block, bowl=_own_bowl(block))
        return _park(state, block)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if step.block in after.blocks and _moved(before, after) and _own_bowl(step.block) not in after.positions:
            return True  # this block should have stayed where it was
        return super().step_moves_away(before, after, step)

    def feasible(self, scene: Scene) -> bool:
        return any(_own_bowl(b) in scene.bowls for b in scene.blocks)


class BowlsExceptRed(_FromBenchmarkScenes, BlockwiseIntention):
    name = "bowls-except-red"
    description = "Put every block in a bowl except the red one, which stays where it is."

    keep = "red block"

    def wanted(self, state: WorldState, rel: Relations, block: str) -> bool:
        if block == self.keep:
            return _flat(rel, block)
        return rel.in_bowl(block) is not None

    def place(self, state: WorldState, rel: Relations, block: str) -> Skill | None:
        if block == self.keep:
            return _park(state, block)
        if not state.bowls:
            return None
        counts = _bowl_counts(state, rel)
        # Spread the blocks over the bowls (short piles are steadier), nearest bowl on ties.
        bowl = min(state.bowls, key=lambda w: (counts[w], _distance(state, block, w)))
        return PutIn(block=block, bowl=bowl)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if step.block == self.keep and _moved(before, after):
            return True
        return super().step_moves_away(before, after, step)

    def feasible(self, scene: Scene) -> bool:
        return self.keep in scene.blocks and len(scene.blocks) >= 2 and bool(scene.bowls)


# ---- two-clause combinations -----------------------------------------------------------------


def _row_rank(block: str) -> float:
    return 0.0  # any order


class WarmInBowlsCoolRow(_FromBenchmarkScenes, Intention):
    name = "warm-in-bowls-cool-row"
    description = (
        "Put the warm-coloured blocks in bowls and line the cool-coloured blocks up in one "
        "left-to-right row on the table."
    )

    @staticmethod
    def cool(state: WorldState) -> list[str]:
        return [b for b in state.blocks if not is_warm(b)]

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if not n:
            return 0.0
        rel = relations(state)
        warm_ok = sum(1 for b in state.blocks if is_warm(b) and rel.in_bowl(b) is not None)
        return (warm_ok + _longest_line(state, rel, self.cool(state), 0, _row_rank)) / n

    def satisfied(self, state: WorldState) -> bool:
        rel = relations(state)
        warm_ok = all(rel.in_bowl(b) is not None for b in state.blocks if is_warm(b))
        return bool(state.blocks) and warm_ok and _line_ok(state, rel, self.cool(state), 0, _row_rank)

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        if is_warm(block):
            return relations(after).in_bowl(block) is None
        return _line_misstep(after, block, self.cool(after), 0, _row_rank)

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if is_warm(b)]
        return bool(warm) and len(warm) < len(scene.blocks) and bool(scene.bowls)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks or not state.bowls:
            return None
        if self.satisfied(state):
            return []
        steps: list[Skill] = []
        current = state
        for b in top_first(state, state.blocks):
            rel = relations(current)
            if is_warm(b) and rel.in_bowl(b) is None:
                counts = _bowl_counts(current, rel)
                step: Skill | None = PutIn(block=b, bowl=min(
                    current.bowls, key=lambda w, b=b: (counts[w], _distance(current, b, w))))
            elif not is_warm(b) and not _flat(rel, b):
                step = _park(current, b)
            else:
                continue
            current = _run(current, step)
            if current is None:
                return None
            steps.append(step)
        cool = self.cool(current)
        if _line_ok(current, relations(current), cool, 0, _row_rank):
            return verified(self, state, steps)
        for check in (_smooth, verified):
            found = _plan_line(current, cool, 0, _row_rank, lambda more, check=check: check(self, state, steps + more))
            if found is not None:
                return found
        return None


class CoolTowerWarmFront(_FromBenchmarkScenes, Intention):
    name = "cool-tower-warm-front"
    description = (
        "Stack the cool-coloured blocks into one tower and put the warm-coloured blocks on the "
        "table along the front edge."
    )

    @staticmethod
    def warm_ok(state: WorldState, rel: Relations, block: str) -> bool:
        return on_table(rel, block) and state.pos(block)[1] <= FRONT_BAND_Y

    @staticmethod
    def cool_tower(state: WorldState, rel: Relations) -> list[str]:
        """The tallest run of cool blocks from the base of a tower standing on the table."""
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

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if not n:
            return 0.0
        rel = relations(state)
        warm = sum(1 for b in state.blocks if is_warm(b) and self.warm_ok(state, rel, b))
        return (warm + len(self.cool_tower(state, rel))) / n

    def satisfied(self, state: WorldState) -> bool:
        return bool(state.blocks) and self.score(state) >= 1.0 - EPS

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - EPS:
            return True
        block = step.block
        if block not in after.blocks or not _moved(before, after):
            return False
        rel = relations(after)
        if is_warm(block):
            return not self.warm_ok(after, rel, block)
        below = rel.below(block)
        if below is None:  # set down on its own: only right when it is the one cool block
            return sum(1 for b in after.blocks if not is_warm(b)) > 1
        return is_warm(below) or block not in self.cool_tower(after, rel)

    def feasible(self, scene: Scene) -> bool:
        warm = [b for b in scene.blocks if is_warm(b)]
        return bool(warm) and len(warm) < len(scene.blocks)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.blocks:
            return None
        if self.satisfied(state):
            return []
        steps: list[Skill] = []
        current = state
        band = grid(INNER_X, (INNER_Y[0], FRONT_BAND_Y - 0.02), step=0.045)
        for b in top_first(state, state.blocks):
            rel = relations(current)
            if is_warm(b) and not self.warm_ok(current, rel, b):
                step = _put_free(current, b, nearest_first(band, current.pos(b)),
                                 accept=lambda s, b=b: self.warm_ok(s, relations(s), b))
            elif not is_warm(b) and not on_table(rel, b) and b not in self.cool_tower(current, rel):
                step = _park(current, b)  # a cool block stacked elsewhere: set it down first
            else:
                continue
            current = _run(current, step)
            if current is None:
                return None
            steps.append(step)
        tower = self.cool_tower(current, relations(current))
        if not tower:
            return None
        top = tower[-1]
        for b in top_first(current, [b for b in current.blocks if not is_warm(b) and b not in tower]):
            steps.append(PutOn(block=b, target=top))
            top = b
        return verified(self, state, steps)


HELDOUT_INTENTIONS: tuple[Intention, ...] = (
    InFrontOfABowl(),
    WarmLeftOfCool(),
    RowDarkToLight(),
    ColumnWarmInFront(),
    TowerWarmUnderCool(),
    AlongTheFrontEdge(),
    BackHalf(),
    FrontCorners(),
    GatheredInTheMiddle(),
    TwoOrMoreInEveryBowl(),
    OneInEachBowlRestStay(),
    MatchOrStay(),
    BowlsExceptRed(),
    WarmInBowlsCoolRow(),
    CoolTowerWarmFront(),
)


def heldout_intentions() -> list[Intention]:
    """A fresh instance of every held-out intention, in the suite's order."""
    return [type(i)() for i in HELDOUT_INTENTIONS]
