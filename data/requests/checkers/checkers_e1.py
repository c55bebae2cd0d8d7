"""Checkers for the pass-3 translation check, writer e1: request text and the world's public API only."""

from __future__ import annotations

import itertools
import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_RADIUS,
    COOL_COLORS,
    WARM_COLORS,
    PutAt,
    PutIn,
    PutOn,
    Scene,
    WorldState,
    apply_skill,
    relations,
    sample_scene,
    table_position_name,
)

# --------------------------------------------------------------------------------------------
# Conventions (from the world module): x runs left (-0.3) to right (+0.3); y runs from the
# front edge, nearest the person (-0.8), to the back edge (-0.2). Thirds of the table follow
# the world's 3x3 grid: back third y > -0.4, front third y < -0.6, middle cell |x| < 0.1 and
# -0.6 < y < -0.4.
# --------------------------------------------------------------------------------------------

RAINBOW = ("red", "orange", "yellow", "green", "blue", "purple")
DULL = frozenset({"gray", "brown"})
BACK_Y = -0.4
FRONT_Y = -0.6
SIDE_VEC = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "front": (0.0, -1.0), "behind": (0.0, 1.0)}
REACH = 0.02
BOWL_CLEAR = BOWL_RADIUS + BLOCK_SIZE / 2 + 0.004  # a block centre closer than this to a bowl is blocked
BLOCK_CLEAR = BLOCK_SIZE + 0.004
BOWL_SIDE = BOWL_RADIUS + BLOCK_SIZE / 2 + 0.012  # where "next to" puts a block beside a bowl
BLOCK_SIDE = BLOCK_SIZE + 0.012  # ... beside a block

_GRID = [
    (round(float(x), 3), round(float(y), 3))
    for x in np.arange(-0.28, 0.2801, 0.02)
    for y in np.arange(-0.78, -0.2199, 0.02)
]


def _kind(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


def _col(name: str) -> str:
    return name.split(" ", 1)[0]


def _fr(name: str) -> float:
    return BOWL_RADIUS if _kind(name) == "bowl" else BLOCK_SIZE / 2


def _xy(state: WorldState, name: str) -> tuple[float, float]:
    p = state.positions[name]
    return (p[0], p[1])


def _dist(a, b) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _blocks(obj) -> list[str]:
    return [n for n in (obj.objects if isinstance(obj, Scene) else obj.positions) if _kind(n) == "block"]


def _bowls(obj) -> list[str]:
    return [n for n in (obj.objects if isinstance(obj, Scene) else obj.positions) if _kind(n) == "bowl"]


def _colors(scene: Scene, kind: str) -> set[str]:
    return {_col(o) for o in scene.objects if _kind(o) == kind}


def _loose(rel, b: str) -> bool:
    """Resting directly on the table (not in a bowl, not on a block) with nothing on top."""
    return b in rel.on_table and rel.above(b) is None


def _side_of(state: WorldState, ref: str, b: str) -> str:
    dx = state.positions[b][0] - state.positions[ref][0]
    dy = state.positions[b][1] - state.positions[ref][1]
    if abs(dx) >= abs(dy):
        return "right" if dx > 0 else "left"
    return "behind" if dy > 0 else "front"


def _on_board(xy) -> bool:
    return -0.285 <= xy[0] <= 0.285 and -0.785 <= xy[1] <= -0.215


def _reachable(xy) -> bool:
    (x0, x1), (y0, y1) = BOUNDS
    return x0 - REACH <= xy[0] <= x1 + REACH and y0 - REACH <= xy[1] <= y1 + REACH


def _bowl_ok(state: WorldState, xy, extra: float = 0.002, edge: bool = False) -> bool:
    """A block could stand at xy as far as the bowls (which never move) and the table edge go
    (``edge``: anywhere the robot reaches, even right at the edge)."""
    if not (_reachable(xy) if edge else _on_board(xy)):
        return False
    return all(_dist(xy, _xy(state, w)) >= BOWL_CLEAR + extra for w in _bowls(state))


def _blockers(state: WorldState, xy, moving: str) -> list[str]:
    """Objects whose footprint would overlap a block put down at xy (as the world's PutAt checks)."""
    out = []
    for o, p in state.positions.items():
        if o == moving:
            continue
        if _kind(o) == "block" and p[2] > BLOCK_SIZE:
            continue
        if math.hypot(p[0] - xy[0], p[1] - xy[1]) < _fr(o) + BLOCK_SIZE / 2 + 0.004:
            out.append(o)
    return out


def _frac(flags) -> float:
    flags = list(flags)
    return float(sum(bool(f) for f in flags)) / len(flags) if flags else 1.0


def _final_score(ok: bool, partial: float) -> float:
    return 1.0 if ok else float(min(0.99, max(0.0, partial)))


def _sample(rng, ok, n_blocks=(2, 3), n_bowls=(1, 2), matching=None, tries=20000) -> Scene:
    for _ in range(tries):
        try:
            sc = sample_scene(rng, n_blocks=n_blocks, n_bowls=n_bowls, matching=matching)
        except ValueError:  # fewer than 3 objects drawn
            continue
        if 3 <= len(sc.objects) <= 5 and ok(sc):
            return sc
    raise RuntimeError("could not sample a feasible scene")


def _stacks(rel, blocks):
    """Each stack (a base with at least one block on it) as a bottom-to-top list."""
    out = []
    for b in blocks:
        if rel.below(b) is None and rel.above(b) is not None:
            chain = [b]
            while (u := rel.above(chain[-1])) is not None:
                chain.append(u)
            out.append(chain)
    return out


def _pairs_ok(state: WorldState) -> tuple[bool, list[str], float]:
    """All blocks in two-block stacks standing on the table: (ok, bases, fraction of blocks in pairs)."""
    rel = relations(state)
    bases, good = [], set()
    for b in state.blocks:
        if b in rel.on_table and (t := rel.above(b)) is not None and rel.above(t) is None:
            bases.append(b)
            good |= {b, t}
    blocks = state.blocks
    return len(good) == len(blocks), bases, len(good) / max(1, len(blocks))


class _Fail(Exception):
    pass


class _P:
    """A little planner: applies each step with the world model and fails loudly."""

    def __init__(self, state: WorldState):
        self.s = state
        self.steps: list = []

    def rel(self):
        return relations(self.s)

    def do(self, step) -> None:
        new, fail = apply_skill(self.s, step)
        if fail is not None:
            raise _Fail(fail.reason)
        self.s = new
        self.steps.append(step)

    def top_of(self, b: str) -> str:
        rel, t = self.rel(), b
        while (u := rel.above(t)) is not None:
            t = u
        return t

    def clear(self, b: str, reserved=(), region=None) -> None:
        for _ in range(12):
            if self.rel().above(b) is None:
                return
            self.park(self.top_of(b), reserved, region)
        raise _Fail("could not clear")

    def free_spots(self, b: str, reserved=(), region=None, margin: float = 0.0):
        return [
            c
            for c in _GRID
            if (region is None or region(c))
            and all(_dist(c, r) >= 0.05 for r in reserved)
            and _bowl_ok(self.s, c, 0.002 + margin)
            and not _blockers(self.s, c, b)
        ]

    def park(self, b: str, reserved=(), region=None, prefer=None) -> None:
        """Move b (after clearing it) onto a free bit of table, away from reserved points."""
        self.clear(b, reserved, region)
        here = prefer if prefer is not None else _xy(self.s, b)
        cands = self.free_spots(b, reserved, region)
        if not cands and region is not None:
            raise _Fail("no room in region")
        if not cands:
            cands = self.free_spots(b, (), None)
        if not cands:
            raise _Fail("no room to park")
        c = min(cands, key=lambda c: _dist(c, here))
        self.do(PutAt(block=b, position=c))

    def place_at(self, b: str, xy, reserved=(), park_region=None) -> None:
        """Put b at xy on the table, moving blocks that are in the way."""
        xy = (float(xy[0]), float(xy[1]))
        self.clear(b, list(reserved) + [xy], park_region)
        for _ in range(8):
            bl = _blockers(self.s, xy, b)
            if not bl:
                self.do(PutAt(block=b, position=xy))
                return
            if any(_kind(o) == "bowl" for o in bl):
                raise _Fail("a bowl is in the way")
            for o in bl:
                if o in _blockers(self.s, xy, b):
                    self.park(o, list(reserved) + [xy], park_region)
        raise _Fail("could not free the spot")

    def place_in_region(self, b: str, region, prefer, reserved=()) -> None:
        self.clear(b, reserved)
        cands = self.free_spots(b, reserved, region)
        if cands:
            self.do(PutAt(block=b, position=min(cands, key=lambda c: _dist(c, prefer))))
            return
        spots = sorted((c for c in _GRID if region(c) and _bowl_ok(self.s, c)), key=lambda c: _dist(c, prefer))
        for c in spots[:30]:
            if _attempt(self, lambda q, c=c: q.place_at(b, c, reserved)):
                return
        raise _Fail("region full")

    def put_in(self, b: str, bowl: str, reserved=()) -> None:
        self.clear(b, reserved)
        self.do(PutIn(block=b, bowl=bowl))

    def put_on(self, b: str, target: str, reserved=()) -> None:
        self.clear(b, reserved)
        self.clear(target, reserved)
        self.do(PutOn(block=b, target=target))

    def fill(self, blocks, bowl: str, reserved=()) -> None:
        """Every block of ``blocks`` into ``bowl``."""
        for _ in range(4 * len(blocks) + 4):
            rel = self.rel()
            todo = [b for b in blocks if rel.in_bowl(b) != bowl]
            if not todo:
                return
            free = [b for b in todo if rel.above(b) is None]
            self.put_in(free[0] if free else todo[0], bowl, reserved)
        raise _Fail("could not fill the bowl")

    def stack(self, order, base_xy=None, reserved=()) -> None:
        """One stack of ``order`` bottom to top (base put at base_xy, else kept where it rests)."""
        base = order[0]
        if base_xy is not None:
            self.place_at(base, base_xy, reserved)
        else:
            self.clear(base, reserved)
            if self.rel().below(base) is not None:
                self.park(base, reserved)
        for lower, upper in zip(order, order[1:]):
            if self.rel().below(upper) == lower and self.rel().above(upper) is None:
                continue
            self.put_on(upper, lower, reserved)


def _attempt(p: _P, fn) -> bool:
    """Run fn on a copy of the planner; keep its steps only if it succeeds."""
    q = _P(p.s)
    try:
        fn(q)
    except _Fail:
        return False
    p.s = q.s
    p.steps.extend(q.steps)
    return True


def _run(intention, state: WorldState, fn):
    p = _P(state)
    try:
        fn(p)
    except _Fail:
        return None
    return p.steps if intention.satisfied(p.s) else None


def _row_greedy(state: WorldState, n: int, y: float, x0: float = -0.27, x1: float = 0.27, pitch: float = 0.055):
    """n points left to right along height y, skipping past bowls."""
    pts, x = [], x0
    while len(pts) < n and x <= x1 + 1e-9:
        if _bowl_ok(state, (x, y), 0.004):
            pts.append((round(x, 4), y))
            x += pitch
        else:
            x += 0.01
    return pts if len(pts) == n else None


def _line(state: WorldState, n: int, starts, step, pitch: float = 0.055):
    """n contiguous points start + i * pitch * step, all clear of bowls and on the table."""
    for s in starts:
        pts = [(round(s[0] + i * pitch * step[0], 4), round(s[1] + i * pitch * step[1], 4)) for i in range(n)]
        if all(_bowl_ok(state, pt, 0.004) for pt in pts):
            return pts
    return None


def _assign(blocks, targets, state):
    """Blocks to target points, minimising total travel (brute force; at most 5 blocks)."""
    best, best_cost = None, math.inf
    for perm in itertools.permutations(range(len(targets)), len(blocks)):
        cost = sum(_dist(_xy(state, b), targets[i]) for b, i in zip(blocks, perm))
        if cost < best_cost:
            best, best_cost = {b: targets[i] for b, i in zip(blocks, perm)}, cost
    return best


def _front_bowl(state: WorldState) -> str | None:
    bowls = _bowls(state)
    return min(bowls, key=lambda w: (state.positions[w][1], w)) if bowls else None


def _in_row_order(state: WorldState, blocks, key) -> bool:
    """Left to right along x the keys never decrease; neighbours at least 2 cm apart in x."""
    seq = sorted(blocks, key=lambda b: state.positions[b][0])
    for a, b in zip(seq, seq[1:]):
        if key(a) > key(b) or state.positions[b][0] - state.positions[a][0] < 0.02:
            return False
    return True


def _rb_index(b: str) -> int:
    c = _col(b)
    return RAINBOW.index(c) if c in RAINBOW else len(RAINBOW)


# ============================================================================================
# "All the blocks in the front-most bowl" (r353, r122, r230 share this reading)
# ============================================================================================


class _FrontBowlAll:
    def satisfied(self, state):
        w = _front_bowl(state)
        if w is None:
            return False
        rel = relations(state)
        return all(rel.in_bowl(b) == w for b in state.blocks)

    def score(self, state):
        w = _front_bowl(state)
        if w is None:
            return 0.0
        rel = relations(state)
        return _final_score(self.satisfied(state), _frac(rel.in_bowl(b) == w for b in state.blocks))

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        w = _front_bowl(state)
        if w is None:
            return None
        return _run(self, state, lambda p: p.fill(p.s.blocks, w))


class R353(_FrontBowlAll, Intention):
    """All blocks inside the bowl whose centre is nearest the front edge (smallest y)."""

    name = "r353"
    description = "Everything in the bowl nearest me, please, that's the one at the front."


class R122(_FrontBowlAll, Intention):
    """All bowls are the same size, so: every block inside the front-most bowl (smallest y)."""

    name = "r122"
    description = "Clean station: all blocks in one single bowl, whichever bowl is biggest or closest to the front."


class R230(_FrontBowlAll, Intention):
    """All blocks inside the bowl nearest the front edge (smallest y), stacking in it is fine."""

    name = "r230"
    description = "All the blocks in one bowl, the one nearest to me at the front. I like to count them in the evening."


# ============================================================================================


def _in_top_right(xy) -> bool:
    return table_position_name(xy) == "top right corner"


class R055(Intention):
    """Blocks with a same-coloured bowl inside it; the others out of bowls in the back-right cell (x > 0.1, y > -0.4), piling allowed."""

    name = "r055"
    description = (
        "Every block goes in the bowl that matches its colour. Anything without a matching bowl "
        "goes to the back right corner, that's the returns area."
    )

    def _good(self, state, rel, b):
        bowl = f"{_col(b)} bowl"
        if bowl in state.positions:
            return rel.in_bowl(b) == bowl
        return rel.in_bowl(b) is None and _in_top_right(_xy(state, b))

    def satisfied(self, state):
        rel = relations(state)
        return all(self._good(state, rel, b) for b in state.blocks)

    def score(self, state):
        rel = relations(state)
        return _final_score(self.satisfied(state), _frac(self._good(state, rel, b) for b in state.blocks))

    def feasible(self, scene):
        return bool(scene.blocks) and bool(_colors(scene, "block") & _colors(scene, "bowl"))

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2), matching=True)

    def plan(self, state):
        def go(p: _P):
            returns = [b for b in p.s.blocks if f"{_col(b)} bowl" not in p.s.positions]
            corner = (0.3, -0.2)
            for b in returns:
                rel = p.rel()
                if rel.in_bowl(b) is None and _in_top_right(_xy(p.s, b)):
                    continue
                region = lambda c: c[0] >= 0.12 and c[1] >= -0.38  # noqa: E731
                p.clear(b)
                spots = p.free_spots(b, (), region)
                if spots:
                    p.do(PutAt(block=b, position=min(spots, key=lambda c: _dist(c, corner))))
                    continue
                there = [o for o in returns if o != b and _in_top_right(_xy(p.s, o)) and p.rel().in_bowl(o) is None]
                if not there:
                    raise _Fail("corner full")
                p.put_on(b, p.top_of(there[0]))
            for _ in range(10):  # blocks in a bowl of another colour come out first
                rel = p.rel()
                wrong = [b for b in p.s.blocks if (w := rel.in_bowl(b)) is not None and _col(w) != _col(b)]
                if not wrong:
                    break
                p.park(p.top_of(wrong[0]))
            for w in p.s.bowls:
                mates = [b for b in p.s.blocks if _col(b) == _col(w)]
                if mates:
                    p.fill(mates, w)

        return _run(self, state, go)


# ============================================================================================


class _RainbowRow:
    """Rainbow-coloured blocks in a row along the back third, in rainbow order left to right."""

    def _row_blocks(self, state):
        raise NotImplementedError

    def feasible(self, scene):
        return sum(_col(b) in RAINBOW for b in scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=(1, 2))

    def _row_ok(self, state, rel, blocks):
        placed = all(_loose(rel, b) and state.positions[b][1] > BACK_Y for b in blocks)
        return placed and _in_row_order(state, blocks, _rb_index)

    def _place_row(self, p: _P, blocks):
        blocks = sorted(blocks, key=lambda b: (_rb_index(b), b))
        pts = None
        for y in (-0.26, -0.28, -0.3, -0.32, -0.34, -0.36, -0.38, -0.24):
            pts = _row_greedy(p.s, len(blocks), y)
            if pts:
                break
        if not pts:
            raise _Fail("no room for the row")
        for b, xy in zip(blocks, pts):
            p.place_at(b, xy, pts, park_region=lambda c: c[1] < -0.44)


class R290(_RainbowRow, Intention):
    """Every block in one row in the back third (y > -0.4), loose on the table: rainbow colours in order left to right, all other colours to the right of them."""

    name = "r290"
    description = (
        "Rainbow order, left to right along the back edge. Red, orange, yellow, green, blue, "
        "purple, then whatever's left at the end."
    )

    def satisfied(self, state):
        rel = relations(state)
        return self._row_ok(state, rel, state.blocks)

    def score(self, state):
        rel = relations(state)
        part = _frac(_loose(rel, b) and state.positions[b][1] > BACK_Y for b in state.blocks)
        part = 0.8 * part + 0.2 * _in_row_order(state, state.blocks, _rb_index)
        return _final_score(self.satisfied(state), part)

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and any(_col(b) in RAINBOW for b in scene.blocks)

    def plan(self, state):
        return _run(self, state, lambda p: self._place_row(p, p.s.blocks))


class R196(_RainbowRow, Intention):
    """Red..purple blocks loose in a row in the back third (y > -0.4), rainbow order left to right; other colours anywhere except in the back third between them."""

    name = "r196"
    description = (
        "Sort them like the paint chip rack: red, orange, yellow, green, blue, purple, left to "
        "right along the back. Skip what's missing."
    )

    def _intruders(self, state, rel, rb):
        if not rb:
            return []
        xs = [state.positions[b][0] for b in rb]
        lo, hi = min(xs), max(xs)
        return [
            b
            for b in state.blocks
            if _col(b) not in RAINBOW
            and state.positions[b][1] > BACK_Y - 0.02
            and lo - 0.02 < state.positions[b][0] < hi + 0.02
        ]

    def satisfied(self, state):
        rel = relations(state)
        rb = [b for b in state.blocks if _col(b) in RAINBOW]
        return bool(rb) and self._row_ok(state, rel, rb) and not self._intruders(state, rel, rb)

    def score(self, state):
        rel = relations(state)
        rb = [b for b in state.blocks if _col(b) in RAINBOW]
        part = _frac(_loose(rel, b) and state.positions[b][1] > BACK_Y for b in rb)
        part = 0.8 * part + 0.2 * _in_row_order(state, rb, _rb_index)
        return _final_score(self.satisfied(state), part)

    def plan(self, state):
        def go(p: _P):
            rb = [b for b in p.s.blocks if _col(b) in RAINBOW]
            self._place_row(p, rb)
            for b in self._intruders(p.s, p.rel(), rb):
                p.park(b, [_xy(p.s, r) for r in rb], region=lambda c: c[1] < -0.46)

        return _run(self, state, go)


# ============================================================================================


class R034(Intention):
    """Every orange and yellow block inside one and the same bowl; other blocks anywhere (even in that bowl)."""

    name = "r034"
    description = (
        "Put all the orange and yellow blocks together in one bowl, the autumn ones. The rest can "
        "go wherever you like."
    )

    @staticmethod
    def _autumn(state):
        return [b for b in state.blocks if _col(b) in ("orange", "yellow")]

    def satisfied(self, state):
        rel = relations(state)
        where = {rel.in_bowl(b) for b in self._autumn(state)}
        return len(where) == 1 and None not in where

    def score(self, state):
        rel = relations(state)
        aut = self._autumn(state)
        if not aut:
            return 0.0
        best = max((sum(rel.in_bowl(b) == w for b in aut) for w in state.bowls), default=0)
        return _final_score(self.satisfied(state), best / len(aut))

    def feasible(self, scene):
        cols = _colors(scene, "block")
        return {"orange", "yellow"} <= cols and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        aut = self._autumn(state)
        if not aut or not state.bowls:
            return None
        rel = relations(state)

        def cost(w):
            return (sum(rel.in_bowl(b) != w for b in aut), sum(_dist(_xy(state, b), _xy(state, w)) for b in aut))

        w = min(state.bowls, key=cost)
        return _run(self, state, lambda p: p.fill(aut, w))


# ============================================================================================


class R346(Intention):
    """No block may rest on another block anywhere (in bowls too): every pile is one block high."""

    name = "r346"
    description = "No tall piles, please. My hands shake and I'll knock them over if I try to take one."

    def satisfied(self, state):
        return not relations(state).on

    def score(self, state):
        rel = relations(state)
        return _final_score(self.satisfied(state), _frac(rel.below(b) is None for b in state.blocks))

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            for _ in range(10):
                on = p.rel().on
                if not on:
                    return
                b = on[0][0]
                p.park(p.top_of(b))
            raise _Fail("too many piles")

        return _run(self, state, go)


# ============================================================================================

FAR_GAP = 0.06  # "well away": at least 6 cm between a leftover block's side and any bowl's rim


def _far_from_bowls(state, xy) -> bool:
    return all(_dist(xy, _xy(state, w)) >= BOWL_RADIUS + BLOCK_SIZE / 2 + FAR_GAP for w in _bowls(state))


class R258(Intention):
    """Every bowl holds exactly one block; every other block rests on the table (not stacked) with >= 6 cm between it and any bowl rim."""

    name = "r258"
    description = (
        "One block per bowl, no cross-contamination. Anything left over stays out on the table, "
        "well away from the bowls."
    )

    def _good(self, state, rel):
        counts = {w: 0 for w in state.bowls}
        for b in state.blocks:
            if (w := rel.in_bowl(b)) is not None:
                counts[w] += 1
        flags = [counts[w] == 1 for w in state.bowls]
        for b in state.blocks:
            if rel.in_bowl(b) is None:
                flags.append(b in rel.on_table and _far_from_bowls(state, _xy(state, b)))
        return flags

    def satisfied(self, state):
        return bool(state.bowls) and all(self._good(state, relations(state)))

    def score(self, state):
        return _final_score(self.satisfied(state), _frac(self._good(state, relations(state))))

    def feasible(self, scene):
        return 1 <= len(scene.bowls) <= len(scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            far = lambda c: _far_from_bowls(p.s, c)  # noqa: E731
            for w in p.s.bowls:  # too many in a bowl: lift the extras out
                for _ in range(6):
                    inside = [b for b in p.s.blocks if p.rel().in_bowl(b) == w]
                    if len(inside) <= 1:
                        break
                    p.park(p.top_of(inside[0]), region=far)
            for w in p.s.bowls:  # empty bowls: the nearest block not yet in a bowl
                rel = p.rel()
                if any(rel.in_bowl(b) == w for b in p.s.blocks):
                    continue
                spare = [b for b in p.s.blocks if rel.in_bowl(b) is None]
                if not spare:
                    raise _Fail("not enough blocks")
                spare.sort(key=lambda b: (rel.above(b) is not None, _dist(_xy(p.s, b), _xy(p.s, w))))
                p.put_in(spare[0], w)
            for _ in range(10):  # leftovers: flat on the table and far from bowls
                rel = p.rel()
                bad = [
                    b
                    for b in p.s.blocks
                    if rel.in_bowl(b) is None and not (b in rel.on_table and far(_xy(p.s, b)))
                ]
                if not bad:
                    return
                b = bad[0]
                if b in rel.on_table:
                    p.place_in_region(b, far, _xy(p.s, b))
                else:
                    p.park(b, region=far)
            raise _Fail("leftovers")

        return _run(self, state, go)


# ============================================================================================


class R053(Intention):
    """Cool blocks (blue, green, purple, cyan, gray) loose on the table in the back third (y > -0.4); warm ones (red, orange, yellow, pink, brown) in the front third (y < -0.6)."""

    name = "r053"
    description = (
        "Put the cool colours along the back edge and the warm ones along the front. Gradient "
        "from front to back basically."
    )

    def _good(self, state, rel, b):
        y = state.positions[b][1]
        if not _loose(rel, b):
            return False
        return y > BACK_Y if _col(b) in COOL_COLORS else y < FRONT_Y

    def satisfied(self, state):
        rel = relations(state)
        return all(self._good(state, rel, b) for b in state.blocks)

    def score(self, state):
        rel = relations(state)
        return _final_score(self.satisfied(state), _frac(self._good(state, rel, b) for b in state.blocks))

    def feasible(self, scene):
        cols = _colors(scene, "block")
        return bool(cols & COOL_COLORS) and bool(cols & WARM_COLORS)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            cool = sorted(b for b in p.s.blocks if _col(b) in COOL_COLORS)
            warm = sorted(b for b in p.s.blocks if _col(b) not in COOL_COLORS)
            targets = {}
            for group, ys in ((cool, (-0.26, -0.29, -0.32, -0.35, -0.38, -0.23)), (warm, (-0.74, -0.71, -0.68, -0.65, -0.62, -0.77))):
                pts = None
                for y in ys:
                    pts = _row_greedy(p.s, len(group), y)
                    if pts:
                        break
                if not pts:
                    raise _Fail("no row")
                # keep left-right roughly as the blocks are now
                for b, xy in zip(sorted(group, key=lambda b: p.s.positions[b][0]), pts):
                    targets[b] = xy
            reserved = list(targets.values())
            for b, xy in targets.items():
                p.place_at(b, xy, reserved, park_region=lambda c: -0.56 < c[1] < -0.44)

        return _run(self, state, go)


# ============================================================================================


def _around_sides(state, ref, others):
    """Side of ref that each block occupies, or None when it is not standing right beside it."""
    rel = relations(state)
    out = {}
    for b in others:
        ok = rel.is_next_to(b, ref) and rel.in_bowl(b) is None and rel.above(b) is None
        if _kind(ref) == "bowl":
            ok = ok and b in rel.on_table
        out[b] = _side_of(state, ref, b) if ok else None
    return out


def _distinct_sides(sides: dict) -> bool:
    vals = list(sides.values())
    return None not in vals and len(set(vals)) == len(vals)


def _surround(p: _P, ref: str, blocks, offset: float) -> None:
    """Put each block on a different side of ref (left, right, front, behind)."""
    c = _xy(p.s, ref)
    spots = {s: (c[0] + offset * v[0], c[1] + offset * v[1]) for s, v in SIDE_VEC.items()}
    spots = {s: xy for s, xy in spots.items() if _bowl_ok(p.s, xy, 0.001, edge=True)}
    if len(spots) < len(blocks):
        raise _Fail("not enough free sides")
    sides = list(spots)
    best, best_cost = None, math.inf
    for perm in itertools.permutations(sides, len(blocks)):
        cost = sum(_dist(_xy(p.s, b), spots[s]) for b, s in zip(blocks, perm))
        if cost < best_cost:
            best, best_cost = dict(zip(blocks, perm)), cost
    reserved = list(spots.values())
    for b, s in best.items():
        p.place_at(b, spots[s], reserved)


class R052(Intention):
    """Some one bowl has every block standing right beside it on the table, each block on a different side (left/right/front/behind); with fewer than 4 blocks, distinct sides suffice."""

    name = "r052"
    description = (
        "Cluster all the blocks around one bowl, one on each side, left, right, front and back. "
        "Like a courtyard plan."
    )

    def satisfied(self, state):
        return any(_distinct_sides(_around_sides(state, w, state.blocks)) for w in state.bowls)

    def score(self, state):
        best = 0.0
        for w in state.bowls:
            sides = _around_sides(state, w, state.blocks)
            got = {s for s in sides.values() if s is not None}
            best = max(best, len(got) / max(1, len(state.blocks)))
        return _final_score(self.satisfied(state), best)

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and 2 <= len(scene.blocks) <= 4

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(3, 4), n_bowls=(1, 2))

    def plan(self, state):
        for w in sorted(state.bowls, key=lambda w: _dist(_xy(state, w), (0.0, -0.5))):
            steps = _run(self, state, lambda p, w=w: _surround(p, w, sorted(p.s.blocks), BOWL_SIDE))
            if steps is not None:
                return steps
        return None


# ============================================================================================


def _pair_up(blocks):
    blocks = sorted(blocks)
    return [(blocks[i], blocks[i + 1]) for i in range(0, len(blocks) - 1, 2)]


def _build_pairs(p: _P, pts) -> None:
    pairs = _pair_up(p.s.blocks)
    bases = [a for a, _ in pairs]
    target = _assign(bases, pts, p.s)
    reserved = list(pts)
    for a in bases:
        p.place_at(a, target[a], reserved)
    for a, b in pairs:
        p.put_on(b, a, reserved)


class R232(Intention):
    """Every block in a two-block stack standing on the table; the stacks' bases in one straight row (aligned within 3 cm, neighbours at most 12 cm apart)."""

    name = "r232"
    description = "Pair the blocks up into duets, one on top of the other, and set the pairs in a row."

    @staticmethod
    def _row(state, bases) -> bool:
        if len(bases) < 2:
            return True
        pts = [_xy(state, b) for b in bases]
        for ax in (0, 1):
            other = 1 - ax
            spread = max(q[other] for q in pts) - min(q[other] for q in pts)
            vals = sorted(q[ax] for q in pts)
            if spread <= 0.03 and all(0.0 < v2 - v1 <= 0.12 for v1, v2 in zip(vals, vals[1:])):
                return True
        return False

    def satisfied(self, state):
        ok, bases, _ = _pairs_ok(state)
        return ok and self._row(state, bases)

    def score(self, state):
        ok, bases, frac = _pairs_ok(state)
        return _final_score(self.satisfied(state), 0.8 * frac + 0.2 * (ok and self._row(state, bases)))

    def feasible(self, scene):
        return len(scene.blocks) >= 4 and len(scene.blocks) % 2 == 0

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=4, n_bowls=(0, 1))

    def plan(self, state):
        k = len(state.blocks) // 2
        if len(state.blocks) % 2:
            return None
        starts = []
        for y in (-0.5, -0.44, -0.56, -0.38, -0.62, -0.32, -0.68, -0.26, -0.74):
            for x0 in sorted(np.arange(-0.27, 0.2701, 0.01), key=lambda x: abs(x + 0.03 * (k - 1))):
                starts.append((float(x0), y))
        pts = _line(state, k, starts, (1.0, 0.0), pitch=0.07)
        if pts is None:
            return None
        return _run(self, state, lambda p: _build_pairs(p, pts))


# ============================================================================================


class R112(Intention):
    """The red..purple blocks present form one stack in rainbow order, red(-most) at the bottom, nothing on the top one; other colours stay out of that stack."""

    name = "r112"
    description = (
        "Stack the blocks by colour like a rainbow: red at the bottom, then orange, yellow, green, "
        "blue, purple on top. Skip whatever's missing."
    )

    @staticmethod
    def _rb(state):
        return sorted((b for b in state.blocks if _col(b) in RAINBOW), key=_rb_index)

    def satisfied(self, state):
        rb = self._rb(state)
        if len(rb) < 1:
            return False
        rel = relations(state)
        if rel.below(rb[0]) is not None or rel.above(rb[-1]) is not None:
            return False
        return all(rel.below(u) == l for l, u in zip(rb, rb[1:]))

    def score(self, state):
        rb = self._rb(state)
        rel = relations(state)
        flags = [rel.below(rb[0]) is None] if rb else []
        flags += [rel.below(u) == l for l, u in zip(rb, rb[1:])]
        return _final_score(self.satisfied(state), _frac(flags))

    def feasible(self, scene):
        return sum(_col(b) in RAINBOW for b in scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=(0, 2))

    def plan(self, state):
        return _run(self, state, lambda p: p.stack(self._rb(p.s)))


# ============================================================================================


class R108(Intention):
    """The gray block is not moved; every other block stands right beside it, each on a different side (left/right/front/behind); blocks beyond four go in a bowl. (Whether the gray block moved cannot be seen from the final table; the plan never moves it.)"""

    name = "r108"
    description = (
        "Leave the gray block alone wherever it is, and put all the other blocks around it \u2014 "
        "one left, one right, one in front, one behind, then any spare ones in a bowl."
    )

    GRAY = "gray block"

    def _parts(self, state):
        others = sorted(b for b in state.blocks if b != self.GRAY)
        sides = _around_sides(state, self.GRAY, others)
        rel = relations(state)
        around = {b: s for b, s in sides.items() if s is not None}
        spares = [b for b in others if b not in around]
        return around, spares, rel

    def satisfied(self, state):
        if self.GRAY not in state.positions:
            return False
        around, spares, rel = self._parts(state)
        if len(set(around.values())) != len(around):
            return False
        if len(around) < min(4, len(around) + len(spares)):
            return False
        return all(rel.in_bowl(b) is not None for b in spares)

    def score(self, state):
        if self.GRAY not in state.positions:
            return 0.0
        around, spares, _ = self._parts(state)
        n = len(around) + len(spares)
        return _final_score(self.satisfied(state), len(set(around.values())) / max(1, min(4, n)))

    def feasible(self, scene):
        others = [b for b in scene.blocks if b != self.GRAY]
        return self.GRAY in scene.blocks and len(others) >= 1 and (len(others) <= 4 or len(scene.bowls) >= 1)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(3, 4), n_bowls=(0, 1))

    def plan(self, state):
        if self.GRAY not in state.positions:
            return None

        def go(p: _P):
            others = sorted(b for b in p.s.blocks if b != self.GRAY)
            ring, spare = others[:4], others[4:]
            if spare:
                if not p.s.bowls:
                    raise _Fail("no bowl for spares")
                p.fill(spare, p.s.bowls[0])
            _surround(p, self.GRAY, ring, BLOCK_SIDE)

        steps = _run(self, state, go)
        if steps is not None and any(s.block == self.GRAY for s in steps):
            return None
        return steps


# ============================================================================================


class R027(Intention):
    """As many block centres left of the table's midline (x < 0) as right of it (x >= 0)."""

    name = "r027"
    description = (
        "I like things balanced. Same number of blocks on the left half of the table as on the "
        "right half, please."
    )

    @staticmethod
    def _counts(state):
        left = sum(state.positions[b][0] < 0 for b in state.blocks)
        return left, len(state.blocks) - left

    def satisfied(self, state):
        left, right = self._counts(state)
        return left == right

    def score(self, state):
        left, right = self._counts(state)
        n = max(1, left + right)
        return _final_score(self.satisfied(state), 1 - abs(left - right) / n)

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and len(scene.blocks) % 2 == 0

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            for _ in range(6):
                left, right = self._counts(p.s)
                if left == right:
                    return
                heavy_left = left > right
                rel = p.rel()
                cands = [
                    b
                    for b in p.s.blocks
                    if (p.s.positions[b][0] < 0) == heavy_left and rel.above(b) is None
                ]
                b = min(cands, key=lambda b: abs(p.s.positions[b][0]))
                x, y = _xy(p.s, b)
                region = (lambda c: c[0] >= 0.05) if heavy_left else (lambda c: c[0] <= -0.05)
                p.place_in_region(b, region, (-x, y))
            raise _Fail("unbalanced")

        return _run(self, state, go)


# ============================================================================================


def _beside_bowl(state, rel, b, bowl, side) -> bool:
    """b stands on the table right beside bowl, on the given side (dominant direction)."""
    if not (b in rel.on_table and rel.is_next_to(b, bowl)):
        return False
    return _side_of(state, bowl, b) == side


def _beside_candidates(state, bowl, side):
    c = _xy(state, bowl)
    v = SIDE_VEC[side]
    out = []
    for d in (BOWL_SIDE, BOWL_SIDE + 0.01, BOWL_SIDE + 0.02):
        for off in (0.0, 0.02, -0.02, 0.04, -0.04, 0.06, -0.06, 0.08, -0.08):
            xy = (c[0] + d * v[0] - off * v[1], c[1] + d * v[1] + off * v[0])
            if _bowl_ok(state, xy, 0.001, edge=True):
                out.append((round(xy[0], 4), round(xy[1], 4)))
    return out


class R008(Intention):
    """The yellow block stands on the table right beside the yellow bowl (rim gap < 5 cm), mainly to its right (dx > |dy|)."""

    name = "r008"
    description = (
        "Could you put the yellow block next to the yellow bowl, on its right? We're practising "
        "left and right at the moment."
    )

    B, W = "yellow block", "yellow bowl"

    def satisfied(self, state):
        if self.B not in state.positions or self.W not in state.positions:
            return False
        return _beside_bowl(state, relations(state), self.B, self.W, "right")

    def score(self, state):
        if self.B not in state.positions or self.W not in state.positions:
            return 0.0
        rel = relations(state)
        part = 0.5 * rel.is_next_to(self.B, self.W) + 0.5 * (_side_of(state, self.W, self.B) == "right")
        return _final_score(self.satisfied(state), part)

    def feasible(self, scene):
        return self.B in scene.objects and self.W in scene.objects

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        if not self.feasible(state.scene):
            return None

        def go(p: _P):
            if self.satisfied(p.s):
                return
            cands = _beside_candidates(p.s, self.W, "right")
            for xy in cands:
                if _attempt(p, lambda q, xy=xy: q.place_at(self.B, xy, [xy])) and self.satisfied(p.s):
                    return
            raise _Fail("no place right of the bowl")

        return _run(self, state, go)


# ============================================================================================


class R026(Intention):
    """If a brown block exists: with a brown bowl, the brown block is inside it; without one, it rests on the table (not on a block, not in a bowl) near the front edge (y < -0.65). No brown block: nothing to do."""

    name = "r026"
    description = (
        "If there's a brown block, put it in the brown bowl, or else by the front edge. Brown's "
        "for the soil, it belongs down low and near."
    )

    B, W = "brown block", "brown bowl"
    FRONT_EDGE = -0.65

    def satisfied(self, state):
        if self.B not in state.positions:
            return True
        rel = relations(state)
        if self.W in state.positions:
            return rel.in_bowl(self.B) == self.W
        return self.B in rel.on_table and state.positions[self.B][1] < self.FRONT_EDGE

    def score(self, state):
        return 1.0 if self.satisfied(state) else 0.0

    def feasible(self, scene):
        return self.B in scene.objects

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            if self.satisfied(p.s):
                return
            if self.W in p.s.positions:
                p.put_in(self.B, self.W)
            else:
                x = p.s.positions[self.B][0]
                p.place_in_region(self.B, lambda c: c[1] <= self.FRONT_EDGE - 0.01, (x, -0.74))

        return _run(self, state, go)


# ============================================================================================


class R218(Intention):
    """If there is a blue bowl, at least one block (any colour) is inside it; otherwise nothing to do."""

    name = "r218"
    description = (
        "My wife always liked the blue bowl to have something in it. If there's a blue bowl, "
        "please put a block in it, any colour will do."
    )

    W = "blue bowl"

    def satisfied(self, state):
        if self.W not in state.positions:
            return True
        rel = relations(state)
        return any(rel.in_bowl(b) == self.W for b in state.blocks)

    def score(self, state):
        return 1.0 if self.satisfied(state) else 0.0

    def feasible(self, scene):
        return self.W in scene.objects and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            if self.satisfied(p.s):
                return
            rel = p.rel()
            w = _xy(p.s, self.W)
            b = min(p.s.blocks, key=lambda b: (rel.above(b) is not None, _dist(_xy(p.s, b), w)))
            p.put_in(b, self.W)

        return _run(self, state, go)


# ============================================================================================


class R213(Intention):
    """Blue, green and cyan blocks all inside the blue bowl; no other block inside it (the others are meant to stay where they were)."""

    name = "r213"
    description = (
        "Blue bowl is the done column. Blue, green and cyan blocks go in there. Everything else "
        "stays put."
    )

    W = "blue bowl"
    DONE = ("blue", "green", "cyan")

    def _flags(self, state):
        rel = relations(state)
        return [(rel.in_bowl(b) == self.W) == (_col(b) in self.DONE) for b in state.blocks]

    def satisfied(self, state):
        return self.W in state.positions and all(self._flags(state))

    def score(self, state):
        if self.W not in state.positions:
            return 0.0
        return _final_score(self.satisfied(state), _frac(self._flags(state)))

    def feasible(self, scene):
        return self.W in scene.objects and any(_col(b) in self.DONE for b in scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        if self.W not in state.positions:
            return None

        def go(p: _P):
            rel = p.rel()
            for b in p.s.blocks:  # something wrongly in the blue bowl must come out
                if rel.in_bowl(b) == self.W and _col(b) not in self.DONE:
                    p.park(b)
            p.fill([b for b in p.s.blocks if _col(b) in self.DONE], self.W)

        return _run(self, state, go)


# ============================================================================================


class R295(Intention):
    """All blocks loose on the table in one straight front-to-back line hugging the left edge: centres at x <= -0.2, x aligned within 2.5 cm, neighbours at most 10 cm apart."""

    name = "r295"
    description = (
        "Could you shelve them, as it were: all the blocks in a neat line along the left edge, "
        "nothing out of place."
    )

    def _flags(self, state, rel):
        return [_loose(rel, b) and state.positions[b][0] <= -0.2 for b in state.blocks]

    def _neat(self, state):
        xs = [state.positions[b][0] for b in state.blocks]
        ys = sorted(state.positions[b][1] for b in state.blocks)
        return max(xs) - min(xs) <= 0.025 and all(0.0 < b - a <= 0.1 for a, b in zip(ys, ys[1:]))

    def satisfied(self, state):
        rel = relations(state)
        return all(self._flags(state, rel)) and self._neat(state)

    def score(self, state):
        rel = relations(state)
        return _final_score(self.satisfied(state), 0.8 * _frac(self._flags(state, rel)) + 0.2 * self._neat(state))

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=(1, 2))

    def plan(self, state):
        n = len(state.blocks)
        starts = []
        for x in (-0.26, -0.24, -0.22, -0.21):
            for y0 in sorted(np.arange(-0.78, -0.2199, 0.01), key=lambda y: abs(y + 0.5 + 0.0275 * (n - 1))):
                starts.append((x, float(y0)))
        pts = _line(state, n, starts, (0.0, 1.0), pitch=0.055)
        if pts is None:
            return None

        def go(p: _P):
            target = _assign(sorted(p.s.blocks, key=lambda b: p.s.positions[b][1]), pts, p.s)
            for b in sorted(target, key=lambda b: p.s.positions[b][0]):
                p.place_at(b, target[b], pts, park_region=lambda c: c[0] > -0.1)

        return _run(self, state, go)


# ============================================================================================


def _middle_bowl(state):
    mids = [w for w in state.bowls if table_position_name(_xy(state, w)) == "middle"]
    return min(mids, key=lambda w: _dist(_xy(state, w), (0.0, -0.5))) if mids else None


def _single_stack(state):
    """The base of one stack that holds every block, else None."""
    rel = relations(state)
    stacks = _stacks(rel, state.blocks)
    if len(stacks) != 1 or len(stacks[0]) != len(state.blocks):
        return None
    return stacks[0][0]


def _middle_spots(state):
    spots = [c for c in _GRID if table_position_name(c) == "middle" and -0.08 <= c[0] <= 0.08 and -0.58 <= c[1] <= -0.42]
    return sorted((c for c in spots if _bowl_ok(state, c, 0.003)), key=lambda c: _dist(c, (0.0, -0.5)))


class R118(Intention):
    """If a bowl's centre is in the middle cell of the table (|x| < 0.1, -0.6 < y < -0.4), every block is inside it; otherwise all blocks form one stack standing on the table in the middle cell."""

    name = "r118"
    description = (
        "If there's a bowl in the middle, fill it with every block. No bowl in the middle? Then "
        "pile them in the middle yourself."
    )

    def satisfied(self, state):
        w = _middle_bowl(state)
        if w is not None:
            rel = relations(state)
            return all(rel.in_bowl(b) == w for b in state.blocks)
        base = _single_stack(state)
        return base is not None and base in relations(state).on_table and table_position_name(_xy(state, base)) == "middle"

    def score(self, state):
        w = _middle_bowl(state)
        rel = relations(state)
        if w is not None:
            part = _frac(rel.in_bowl(b) == w for b in state.blocks)
        else:
            part = _frac(table_position_name(_xy(state, b)) == "middle" and rel.in_bowl(b) is None for b in state.blocks)
        return _final_score(self.satisfied(state), part * 0.9)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        w = _middle_bowl(state)
        if w is not None:
            return _run(self, state, lambda p: p.fill(p.s.blocks, w))
        return _tower_in_middle(self, state)


def _tower_in_middle(intention, state):
    order = sorted(state.blocks)
    for spot in _middle_spots(state)[:12]:
        steps = _run(intention, state, lambda p, spot=spot: p.stack(order, spot))
        if steps is not None:
            return steps
    return None


# ============================================================================================


class R360(Intention):
    """Every brown and gray block sits in the back third of the table (y > -0.4); others anywhere."""

    name = "r360"
    description = "Please keep the brown and gray ones at the back. They're dull, I don't need them up front."

    def _dull(self, state):
        return [b for b in state.blocks if _col(b) in DULL]

    def satisfied(self, state):
        d = self._dull(state)
        return bool(d) and all(state.positions[b][1] > BACK_Y for b in d)

    def score(self, state):
        d = self._dull(state)
        return _final_score(self.satisfied(state), _frac(state.positions[b][1] > BACK_Y for b in d))

    def feasible(self, scene):
        return any(_col(b) in DULL for b in scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            for b in self._dull(p.s):
                if p.s.positions[b][1] > BACK_Y:
                    continue
                p.place_in_region(b, lambda c: c[1] >= -0.38, (p.s.positions[b][0], -0.28))

        return _run(self, state, go)


# ============================================================================================


class R332(Intention):
    """At least one stack exists; every stack's bottom block is gray or brown and no gray/brown block sits on a brighter one (dull colours low, bright on top)."""

    name = "r332"
    description = (
        "Gray and brown blocks on the bottom of any stack. Solid colours down below, bright stuff on top."
    )

    def _flags(self, state):
        rel = relations(state)
        stacks = _stacks(rel, state.blocks)
        flags = [_col(s[0]) in DULL for s in stacks]
        flags += [not (_col(u) in DULL and _col(l) not in DULL) for u, l in rel.on]
        return stacks, flags

    def satisfied(self, state):
        stacks, flags = self._flags(state)
        return bool(stacks) and all(flags)

    def score(self, state):
        stacks, flags = self._flags(state)
        return _final_score(self.satisfied(state), _frac(flags) if stacks else 0.0)

    def feasible(self, scene):
        cols = [_col(b) for b in scene.blocks]
        return any(c in DULL for c in cols) and any(c not in DULL for c in cols)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        dull = sorted(b for b in state.blocks if _col(b) in DULL)
        bright = sorted(b for b in state.blocks if _col(b) not in DULL)
        if not dull or not bright:
            return None
        return _run(self, state, lambda p: p.stack(dull + bright))


# ============================================================================================


def _in_back_left(xy) -> bool:
    return table_position_name(xy) == "top left corner"


class R319(Intention):
    """Every block in a two-block stack standing on the table, and every stack in the back-left cell (x < -0.1, y > -0.4)."""

    name = "r319"
    description = "All blocks to the back-left corner, stacked in pairs. Pairs only, like buddy runs."

    def satisfied(self, state):
        ok, bases, _ = _pairs_ok(state)
        return ok and all(_in_back_left(_xy(state, b)) for b in bases)

    def score(self, state):
        _, _, frac = _pairs_ok(state)
        corner = _frac(_in_back_left(_xy(state, b)) for b in state.blocks)
        return _final_score(self.satisfied(state), 0.5 * frac + 0.5 * corner)

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and len(scene.blocks) % 2 == 0

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=(0, 2))

    def plan(self, state):
        k = len(state.blocks) // 2
        if len(state.blocks) % 2:
            return None
        spots = sorted(
            (c for c in _GRID if -0.28 <= c[0] <= -0.12 and -0.38 <= c[1] <= -0.22 and _bowl_ok(state, c, 0.003)),
            key=lambda c: _dist(c, (-0.3, -0.2)),
        )
        pts = []
        for c in spots:
            if all(_dist(c, q) >= 0.055 for q in pts):
                pts.append(c)
            if len(pts) == k:
                break
        if len(pts) < k:
            return None
        return _run(self, state, lambda p: _build_pairs(p, pts))


# ============================================================================================


class R227(Intention):
    """Every bowl has its own block (a different one per bowl) standing on the table right beside it on its left (dominant direction); other blocks anywhere."""

    name = "r227"
    description = "A block beside each bowl, to its left, like a page-turner sitting next to the pianist."

    def _ok_sets(self, state):
        rel = relations(state)
        return {w: {b for b in state.blocks if _beside_bowl(state, rel, b, w, "left")} for w in state.bowls}

    @staticmethod
    def _matched(sets) -> int:
        bowls = list(sets)
        for k in range(len(bowls), 0, -1):
            for sub in itertools.combinations(bowls, k):
                for pick in itertools.product(*(sorted(sets[w]) for w in sub)):
                    if len(set(pick)) == k:
                        return k
        return 0

    def satisfied(self, state):
        sets = self._ok_sets(state)
        return bool(sets) and self._matched(sets) == len(sets)

    def score(self, state):
        sets = self._ok_sets(state)
        return _final_score(self.satisfied(state), self._matched(sets) / max(1, len(sets)))

    def feasible(self, scene):
        return 1 <= len(scene.bowls) <= len(scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            used: set[str] = set()
            bowls = sorted(p.s.bowls, key=lambda w: p.s.positions[w][0])
            main = [c[0] for w in bowls if (c := _beside_candidates(p.s, w, "left"))]
            for w in bowls:
                rel = p.rel()
                have = [b for b in p.s.blocks if b not in used and _beside_bowl(p.s, rel, b, w, "left")]
                if have:
                    used.add(have[0])
                    continue
                free = sorted(
                    (b for b in p.s.blocks if b not in used),
                    key=lambda b: _dist(_xy(p.s, b), _xy(p.s, w)),
                )
                done = False
                for b in free:
                    for xy in _beside_candidates(p.s, w, "left"):
                        others = [m for m in main if _dist(m, xy) > 1e-6]
                        ok = _attempt(p, lambda q, b=b, xy=xy: q.place_at(b, xy, others + [xy]))
                        if ok and _beside_bowl(p.s, p.rel(), b, w, "left"):
                            used.add(b)
                            done = True
                            break
                    if done:
                        break
                if not done:
                    raise _Fail("no block fits left of the bowl")

        return _run(self, state, go)


# ============================================================================================


class R083(Intention):
    """Every bowl holds exactly one block, of a colour different from the bowl's; blocks left over stay out of bowls."""

    name = "r083"
    description = "Each bowl gets one block that's a different colour from it. Like little colour swatches."

    def _flags(self, state):
        rel = relations(state)
        flags = []
        for w in state.bowls:
            inside = [b for b in state.blocks if rel.in_bowl(b) == w]
            flags.append(len(inside) == 1 and _col(inside[0]) != _col(w))
        return flags

    def satisfied(self, state):
        return bool(state.bowls) and all(self._flags(state))

    def score(self, state):
        return _final_score(self.satisfied(state), _frac(self._flags(state)))

    @staticmethod
    def _matching(bowls, blocks):
        for perm in itertools.permutations(blocks, len(bowls)):
            if all(_col(b) != _col(w) for b, w in zip(perm, bowls)):
                return dict(zip(bowls, perm))
        return None

    def feasible(self, scene):
        return 1 <= len(scene.bowls) <= len(scene.blocks) and self._matching(scene.bowls, scene.blocks) is not None

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        def go(p: _P):
            bowls = p.s.bowls
            for w in bowls:  # at most one block per bowl before choosing
                for _ in range(6):
                    rel = p.rel()
                    inside = [b for b in p.s.blocks if rel.in_bowl(b) == w]
                    if len(inside) <= 1:
                        break
                    p.park(p.top_of(inside[0]))
            rel = p.rel()
            best, best_cost = None, math.inf
            for perm in itertools.permutations(p.s.blocks, len(bowls)):
                if all(_col(b) != _col(w) for b, w in zip(perm, bowls)):
                    cost = sum(
                        0.0 if rel.in_bowl(b) == w else 1.0 + _dist(_xy(p.s, b), _xy(p.s, w))
                        for b, w in zip(perm, bowls)
                    )
                    if cost < best_cost:
                        best, best_cost = dict(zip(bowls, perm)), cost
            if best is None:
                raise _Fail("no colour-different assignment")
            for b in p.s.blocks:  # out of bowls that are not theirs
                w = p.rel().in_bowl(b)
                if w is not None and best[w] != b:
                    p.park(b)
            for w, b in best.items():
                if p.rel().in_bowl(b) != w:
                    p.put_in(b, w)

        return _run(self, state, go)


# ============================================================================================


class R004(Intention):
    """One stack holding every block, its base standing on the table (not in a bowl) in the middle cell (|x| < 0.1, -0.6 < y < -0.4)."""

    name = "r004"
    description = (
        "Please make one tall tower out of all the blocks in the middle of the table. The kids "
        "love knocking it down after breakfast."
    )

    def satisfied(self, state):
        base = _single_stack(state)
        return base is not None and base in relations(state).on_table and table_position_name(_xy(state, base)) == "middle"

    def score(self, state):
        rel = relations(state)
        stacks = _stacks(rel, state.blocks)
        tallest = max((len(s) for s in stacks), default=1)
        mid = _frac(table_position_name(_xy(state, b)) == "middle" for b in state.blocks)
        return _final_score(self.satisfied(state), 0.5 * tallest / max(1, len(state.blocks)) + 0.5 * mid)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=(0, 2))

    def plan(self, state):
        return _tower_in_middle(self, state)


# ============================================================================================


class R239(Intention):
    """Pink and cyan blocks side by side at the same level, out of bowls, faces at most ~2 cm apart (centres <= 6 cm along one axis, offset <= 2.5 cm across)."""

    name = "r239"
    description = "Keep the pink and cyan blocks touching, side by side. Best combo ever, no notes."

    A, B = "pink block", "cyan block"

    def _measure(self, state):
        pa, pb = state.positions[self.A], state.positions[self.B]
        dx, dy, dz = abs(pa[0] - pb[0]), abs(pa[1] - pb[1]), abs(pa[2] - pb[2])
        return dx, dy, dz

    def satisfied(self, state):
        if self.A not in state.positions or self.B not in state.positions:
            return False
        rel = relations(state)
        if rel.in_bowl(self.A) is not None or rel.in_bowl(self.B) is not None:
            return False
        dx, dy, dz = self._measure(state)
        return dz < 0.012 and max(dx, dy) <= 0.06 and min(dx, dy) <= 0.025

    def score(self, state):
        if self.A not in state.positions or self.B not in state.positions:
            return 0.0
        dx, dy, _ = self._measure(state)
        d = math.hypot(dx, dy)
        return _final_score(self.satisfied(state), max(0.0, 1 - (d - 0.052) / 0.5))

    def feasible(self, scene):
        return self.A in scene.objects and self.B in scene.objects

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        if not self.feasible(state.scene):
            return None

        def beside(p: _P, mover, anchor):
            rel = p.rel()
            if anchor not in rel.on_table:
                raise _Fail("anchor not on the table")
            c = _xy(p.s, anchor)
            here = _xy(p.s, mover)
            spots = [(c[0] + BLOCK_SIDE * v[0], c[1] + BLOCK_SIDE * v[1]) for v in SIDE_VEC.values()]
            spots = sorted((s for s in spots if _bowl_ok(p.s, s, 0.001, edge=True)), key=lambda s: _dist(s, here))
            for s in spots:
                if _attempt(p, lambda q, s=s: q.place_at(mover, s, [s])):
                    return
            raise _Fail("no side free")

        def go(p: _P):
            if self.satisfied(p.s):
                return
            for mover, anchor in ((self.A, self.B), (self.B, self.A)):
                if _attempt(p, lambda q, m=mover, a=anchor: beside(q, m, a)):
                    return
            p.park(self.B, prefer=(0.0, -0.5))
            beside(p, self.A, self.B)

        return _run(self, state, go)


ALL = [
    R353, R055, R290, R034, R346, R258, R053, R052, R232, R122, R112, R108, R027, R008,
    R026, R218, R213, R295, R118, R230, R360, R196, R332, R319, R227, R083, R004, R239,
]
