"""Second independent checkers, writer d1: request text and the world's public API only."""

from __future__ import annotations

from collections.abc import Callable, Iterable

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
    Skill,
    WorldState,
    apply_skill,
    relations,
    sample_scene,
    table_position_name,
)

# --------------------------------------------------------------------------------------------
# geometry and state helpers
# --------------------------------------------------------------------------------------------

(X_LEFT, X_RIGHT), (Y_FRONT, Y_BACK) = BOUNDS  # x: left -> right, y: front (bottom) -> back (top)
TABLE_Z = BLOCK_SIZE / 2
BOWL_CLEAR = BOWL_RADIUS + BLOCK_SIZE / 2 + 0.004  # a block closer than this to a bowl centre collides
CORNERS = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")
CORNER_POINTS = {
    "top left corner": (-0.25, -0.25),
    "top right corner": (0.25, -0.25),
    "bottom left corner": (-0.25, -0.75),
    "bottom right corner": (0.25, -0.75),
}
CENTRE = (0.0, -0.5)


def _color(name: str) -> str:
    return name.split(" ", 1)[0]


def _xy(state: WorldState, name: str) -> np.ndarray:
    p = state.positions[name]
    return np.array([p[0], p[1]], dtype=float)


def _z(state: WorldState, name: str) -> float:
    return float(state.positions[name][2])


def _dist(a: Iterable[float], b: Iterable[float]) -> float:
    a, b = tuple(a), tuple(b)
    return float(np.hypot(a[0] - b[0], a[1] - b[1]))


def _on_table(state: WorldState, block: str) -> bool:
    """Resting directly on the table top (not in a bowl, not on another block)."""
    return block in relations(state).on_table


def _cell(state: WorldState, name: str) -> str:
    return table_position_name(_xy(state, name))


def _in_cell(p: Iterable[float], cell: str) -> bool:
    return table_position_name(tuple(p)) == cell


def _grid(xlo: float, xhi: float, ylo: float, yhi: float, step: float = 0.02) -> list[tuple[float, float]]:
    xs = np.arange(xlo, xhi + 1e-9, step)
    ys = np.arange(ylo, yhi + 1e-9, step)
    return [(round(float(x), 4), round(float(y), 4)) for x in xs for y in ys]


TABLE_GRID = _grid(X_LEFT + 0.03, X_RIGHT - 0.03, Y_FRONT + 0.03, Y_BACK - 0.03)


def _near(cands: Iterable[tuple[float, float]], p: Iterable[float]) -> list[tuple[float, float]]:
    p = tuple(p)
    return sorted(cands, key=lambda c: (_dist(c, p), c))


def _bowl_free(state: WorldState, p: Iterable[float], margin: float = 0.003) -> bool:
    return all(_dist(p, _xy(state, w)) >= BOWL_CLEAR + margin for w in state.bowls)


def _count_in(state: WorldState, bowl: str) -> int:
    return sum(1 for _, w in relations(state).inside if w == bowl)


def _sample(rng: np.random.Generator, ok: Callable[[Scene], bool], **kw) -> Scene:
    for _ in range(5000):
        scene = sample_scene(rng, **kw)
        if ok(scene):
            return scene
    raise RuntimeError("could not sample a feasible scene")


def _frac(flags: list[bool]) -> float:
    return float(np.mean(flags)) if flags else 1.0


class _Planner:
    """Applies skills one by one to a predicted state, keeping only those that succeed."""

    def __init__(self, state: WorldState):
        self.state = state
        self.steps: list[Skill] = []

    def do(self, skill: Skill) -> bool:
        new, fail = apply_skill(self.state, skill)
        if fail is not None:
            return False
        self.state = new
        self.steps.append(skill)
        return True

    def put_at(self, block: str, p: Iterable[float]) -> bool:
        p = tuple(p)
        return self.do(PutAt(block=block, position=(round(float(p[0]), 4), round(float(p[1]), 4))))

    def put_at_any(self, block: str, cands: Iterable[tuple[float, float]]) -> tuple[float, float] | None:
        if relations(self.state).above(block):
            return None
        for c in cands:
            if self.put_at(block, c):
                return c
        return None

    def top_above(self, block: str) -> str | None:
        rel = relations(self.state)
        top = rel.above(block)
        if top is None:
            return None
        while (nxt := rel.above(top)) is not None:
            top = nxt
        return top

    def park(self, block: str, avoid: Callable[[tuple[float, float]], bool] | None = None) -> bool:
        """Put a block down on a free spot of the table near where it is (not where ``avoid``)."""
        cands = [c for c in TABLE_GRID if not (avoid and avoid(c))]
        return self.put_at_any(block, _near(cands, _xy(self.state, block))) is not None

    def clear(self, block: str, avoid: Callable[[tuple[float, float]], bool] | None = None) -> bool:
        """Park whatever stands on ``block``."""
        for _ in range(12):
            top = self.top_above(block)
            if top is None:
                return True
            if not self.park(top, avoid):
                return False
        return self.top_above(block) is None

    def unstack_all(self, avoid: Callable[[tuple[float, float]], bool] | None = None) -> bool:
        for _ in range(12):
            rel = relations(self.state)
            if not rel.on:
                return True
            top = max((a for a, _ in rel.on), key=lambda b: _z(self.state, b))
            if not self.park(top, avoid):
                return False
        return not relations(self.state).on

    def achieve(self, targets: dict[str, tuple[float, float]], avoid_radius: float = 0.06) -> bool:
        """Move each block to its target point on the table (any order that works)."""

        def done(b: str) -> bool:
            return _dist(_xy(self.state, b), targets[b]) < 1e-6 and _on_table(self.state, b)

        pending = [b for b in targets if not done(b)]
        pending.sort(key=lambda b: -_z(self.state, b))
        parked: set[str] = set()
        for _ in range(4 * len(targets) + 6):
            if not pending:
                return True
            progress = False
            for b in list(pending):
                if self.put_at(b, targets[b]):
                    pending.remove(b)
                    progress = True
            if progress:
                continue
            # deadlock: move a pending block that sits on someone's target out of the way
            tpts = list(targets.values())

            def away(c: tuple[float, float]) -> bool:
                return any(_dist(c, t) < avoid_radius for t in tpts)

            movable = [b for b in pending if relations(self.state).above(b) is None and b not in parked]
            movable.sort(key=lambda b: min(_dist(_xy(self.state, b), t) for t in tpts))
            if not movable or not self.park(movable[0], away):
                return False
            parked.add(movable[0])
        return not pending


def _finish(intent: Intention, planner: _Planner) -> list[Skill] | None:
    return planner.steps if intent.satisfied(planner.state) else None


# --------------------------------------------------------------------------------------------
# shared pieces for "every block in region R" requests
# --------------------------------------------------------------------------------------------


def _region_plan(
    intent: Intention,
    state: WorldState,
    ok: Callable[[WorldState, str], bool],
    cands_for: Callable[[WorldState, str], list[tuple[float, float]]],
    region: Callable[[tuple[float, float]], bool],
) -> list[Skill] | None:
    """Move every block that is not ``ok`` to a free candidate point; fall back to a bowl whose
    centre lies in ``region`` or to the top of a block in ``region``."""
    if intent.satisfied(state):
        return []
    P = _Planner(state)
    for _ in range(3):
        bad = [b for b in P.state.blocks if not ok(P.state, b)]
        if not bad:
            break
        bad.sort(key=lambda b: -_z(P.state, b))
        for b in bad:
            if ok(P.state, b):
                continue
            if not P.clear(b, lambda c: not region(c)):
                continue
            if P.put_at_any(b, cands_for(P.state, b)) is not None:
                continue
            bowls = [w for w in P.state.bowls if region(tuple(_xy(P.state, w)))]
            if any(P.do(PutIn(block=b, bowl=w)) for w in bowls):
                continue
            rel = relations(P.state)
            tops = [
                o for o in P.state.blocks
                if o != b and rel.above(o) is None and ok(P.state, o) and region(tuple(_xy(P.state, o)))
            ]
            for o in tops:
                if P.do(PutOn(block=b, target=o)):
                    break
    return _finish(intent, P)


# --------------------------------------------------------------------------------------------
# the checkers
# --------------------------------------------------------------------------------------------


class R012(Intention):
    """Reading: the green block's centre ends in the front-right (bottom right) corner cell of the
    3×3 table grid (on the table or in a bowl there); other blocks are unconstrained."""

    name = "r012"
    description = "Whatever green block there is, put it in the front right corner. That's Sam's spot."
    CELL = "bottom right corner"

    def _ok(self, state: WorldState, b: str) -> bool:
        return _cell(state, b) == self.CELL

    def satisfied(self, state: WorldState) -> bool:
        return "green block" in state.positions and self._ok(state, "green block")

    def score(self, state: WorldState) -> float:
        return float(self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return "green block" in scene.blocks

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if "green block" not in state.positions:
            return None
        if self.satisfied(state):
            return []
        region = lambda c: _in_cell(c, self.CELL)  # noqa: E731
        cands = _near([c for c in _grid(0.11, 0.29, -0.79, -0.61) if region(c)], CORNER_POINTS[self.CELL])
        steps = _region_plan(
            self, state, lambda s, b: b != "green block" or self._ok(s, b), lambda s, b: cands, region
        )
        if steps is not None:
            return steps
        # make room: park other blocks out of the corner, then try again
        P = _Planner(state)
        for o in sorted(P.state.blocks, key=lambda b: -_z(P.state, b)):
            if o != "green block" and region(tuple(_xy(P.state, o))):
                P.park(o, region)
        rest = _region_plan(
            self, P.state, lambda s, b: b != "green block" or self._ok(s, b), lambda s, b: cands, region
        )
        return None if rest is None else P.steps + rest


class R018(Intention):
    """Reading: every block's centre lies in the back third of the table (y ≥ -0.40, within
    20 cm of the back edge), so the front two thirds are free of blocks; bowls are ignored."""

    name = "r018"
    description = "Just tidy all the blocks to the back edge so there's room at the front for homework."
    Y_MIN = -0.40

    def _ok(self, state: WorldState, b: str) -> bool:
        return _xy(state, b)[1] >= self.Y_MIN

    def satisfied(self, state: WorldState) -> bool:
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        base = _grid(-0.27, 0.27, -0.37, -0.23, 0.02)

        def cands(s: WorldState, b: str) -> list[tuple[float, float]]:
            x = _xy(s, b)[0]
            return sorted(base, key=lambda c: (round(-c[1], 2) > 0.26, abs(c[0] - x), -c[1]))

        return _region_plan(self, state, self._ok, cands, lambda c: c[1] >= self.Y_MIN)


class R025(Intention):
    """Reading: the red block sits in the front-left (bottom left) corner cell, on its own: no
    other block in that cell, none stacked with it or next to it; other blocks free elsewhere."""

    name = "r025"
    description = (
        "Keep the red ones apart from the others, in the bottom left corner. "
        "Tomatoes always get their own bed in my garden."
    )
    CELL = "bottom left corner"
    RED = "red block"

    def _red_ok(self, state: WorldState) -> bool:
        if _cell(state, self.RED) != self.CELL:
            return False
        rel = relations(state)
        if rel.above(self.RED) or rel.below(self.RED):
            return False
        return not any(rel.is_next_to(self.RED, o) for o in state.blocks if o != self.RED)

    def _other_ok(self, state: WorldState, b: str) -> bool:
        return _cell(state, b) != self.CELL

    def satisfied(self, state: WorldState) -> bool:
        if self.RED not in state.positions:
            return False
        return self._red_ok(state) and all(self._other_ok(state, b) for b in state.blocks if b != self.RED)

    def score(self, state: WorldState) -> float:
        if self.RED not in state.positions:
            return 0.0
        return _frac([self._red_ok(state)] + [self._other_ok(state, b) for b in state.blocks if b != self.RED])

    def feasible(self, scene: Scene) -> bool:
        return self.RED in scene.blocks and len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.RED not in state.positions:
            return None
        if self.satisfied(state):
            return []
        P = _Planner(state)
        region = lambda c: _in_cell(c, self.CELL)  # noqa: E731
        # keep others out of the corner, with a little margin
        outside = lambda c: c[0] < -0.06 and c[1] < -0.56  # noqa: E731
        P.clear(self.RED)
        for o in sorted(P.state.blocks, key=lambda b: -_z(P.state, b)):
            if o != self.RED and (region(tuple(_xy(P.state, o))) or _dist(_xy(P.state, o), _xy(P.state, self.RED)) < 0.1):
                P.clear(o, outside)
                P.park(o, outside)
        cands = _near([c for c in _grid(-0.29, -0.11, -0.79, -0.61) if region(c)], CORNER_POINTS[self.CELL])
        if not self._red_ok(P.state):
            others = [o for o in P.state.blocks if o != self.RED]
            cands = [c for c in cands if all(_dist(c, _xy(P.state, o)) > 0.1 for o in others)]
            P.put_at_any(self.RED, cands)
        return _finish(self, P)


class _BesideBowl(Intention):
    """Each block with a same-coloured bowl goes on the table at one side of that bowl."""

    SIDE = (1.0, 0.0)
    GAP = 0.06  # rim-to-block-face gap that still reads as "next to"

    def _pairs(self, state_or_scene) -> list[tuple[str, str]]:
        bowls = {_color(w): w for w in state_or_scene.bowls}
        return [(b, bowls[_color(b)]) for b in state_or_scene.blocks if _color(b) in bowls]

    def _ok(self, state: WorldState, b: str, w: str) -> bool:
        if not _on_table(state, b):
            return False
        d = _xy(state, b) - _xy(state, w)
        v = np.array(self.SIDE)
        u = np.array([-v[1], v[0]])
        along, across = float(d @ v), float(d @ u)
        gap = float(np.hypot(*d)) - BOWL_RADIUS - BLOCK_SIZE / 2
        return along > 0 and abs(across) <= along and gap < self.GAP

    def satisfied(self, state: WorldState) -> bool:
        pairs = self._pairs(state)
        return bool(pairs) and all(self._ok(state, b, w) for b, w in pairs)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b, w) for b, w in self._pairs(state)])

    def feasible(self, scene: Scene) -> bool:
        return bool(self._pairs(scene))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible, matching=True)

    def _cands(self, state: WorldState, w: str) -> list[tuple[float, float]]:
        c = _xy(state, w)
        v = np.array(self.SIDE)
        u = np.array([-v[1], v[0]])
        base = BOWL_RADIUS + BLOCK_SIZE / 2 + 0.012
        out = []
        for along in np.arange(base, BOWL_RADIUS + BLOCK_SIZE / 2 + self.GAP - 0.004, 0.008):
            for across in np.arange(-0.07, 0.0701, 0.01):
                p = c + along * v + across * u
                gap = float(np.hypot(along, across)) - BOWL_RADIUS - BLOCK_SIZE / 2
                if abs(across) > 0.9 * along or gap >= self.GAP - 0.004:
                    continue
                if not (X_LEFT - 0.015 <= p[0] <= X_RIGHT + 0.015 and Y_FRONT - 0.015 <= p[1] <= Y_BACK + 0.015):
                    continue
                out.append(((round(float(p[0]), 4), round(float(p[1]), 4)), abs(across), along))
        out.sort(key=lambda t: (t[1], t[2]))
        return [t[0] for t in out]

    def plan(self, state: WorldState) -> list[Skill] | None:
        pairs = self._pairs(state)
        if not pairs:
            return None
        if self.satisfied(state):
            return []
        P = _Planner(state)
        spots = {w: self._cands(state, w) for _, w in pairs}
        key_pts = [s[0] for s in spots.values() if s]

        def near_spot(c: tuple[float, float]) -> bool:
            return any(_dist(c, k) < 0.11 for k in key_pts)

        for _ in range(3):
            for b, w in pairs:
                if self._ok(P.state, b, w):
                    continue
                P.clear(b, near_spot)
                if P.put_at_any(b, spots[w]) is not None and self._ok(P.state, b, w):
                    continue
                # move blocks (not already placed well) that crowd this side of the bowl
                placed = {x for x, y in pairs if self._ok(P.state, x, y)}
                crowd = [
                    o for o in P.state.blocks
                    if o != b and o not in placed and spots[w] and _dist(_xy(P.state, o), spots[w][0]) < 0.13
                ]
                for o in sorted(crowd, key=lambda o: -_z(P.state, o)):
                    P.clear(o, near_spot)
                    P.park(o, near_spot)
                P.put_at_any(b, spots[w])
            if self.satisfied(P.state):
                break
        return _finish(self, P)


class R030(_BesideBowl):
    """Reading: each block that has a same-coloured bowl rests on the table just right of it
    (within 45° of +x, rim gap < 6 cm), not in it; blocks without a matching bowl are free."""

    name = "r030"
    description = (
        "Every block should sit to the right of the bowl that matches it, not in it, "
        "like a figure next to its label."
    )
    SIDE = (1.0, 0.0)
    GAP = 0.06


class R048(_BesideBowl):
    """Reading: each block with a same-coloured bowl rests on the table behind it (towards the
    back edge, within 45° of +y, rim gap < 10 cm); blocks without a matching bowl are free."""

    name = "r048"
    description = (
        "Put each block behind the bowl of the same colour. "
        "Feels like a proper elevation, objects in front, blocks behind."
    )
    SIDE = (0.0, 1.0)
    GAP = 0.10


def _single_pile(state: WorldState, members: list[str]) -> bool:
    """The members form exactly one stack made of nothing but them."""
    rel = relations(state)
    mem = set(members)
    bottoms = [b for b in members if rel.below(b) not in mem]
    if len(bottoms) != 1:
        return False
    if rel.below(bottoms[0]) is not None:  # the pile stands on a non-member
        return False
    for b in members:
        a = rel.above(b)
        if a is not None and a not in mem:
            return False
    return True


class R050(Intention):
    """Reading: each block with a same-coloured bowl is in that bowl; blocks without one
    ("leftovers") form a single stack on the table in the back-left (top left) corner cell."""

    name = "r050"
    description = (
        "Monochrome zoning: every block into a bowl of its colour. "
        "Leftovers stacked neatly in the back left corner."
    )
    CELL = "top left corner"

    def _split(self, state: WorldState) -> tuple[dict[str, str], list[str]]:
        bowls = {_color(w): w for w in state.bowls}
        matched = {b: bowls[_color(b)] for b in state.blocks if _color(b) in bowls}
        return matched, [b for b in state.blocks if b not in matched]

    def _leftover_ok(self, state: WorldState, b: str) -> bool:
        return relations(state).in_bowl(b) is None and _cell(state, b) == self.CELL

    def satisfied(self, state: WorldState) -> bool:
        matched, left = self._split(state)
        rel = relations(state)
        if any(rel.in_bowl(b) != w for b, w in matched.items()):
            return False
        if not all(self._leftover_ok(state, b) for b in left):
            return False
        return len(left) <= 1 or _single_pile(state, left)

    def score(self, state: WorldState) -> float:
        matched, left = self._split(state)
        rel = relations(state)
        flags = [rel.in_bowl(b) == w for b, w in matched.items()]
        pile = len(left) <= 1 or _single_pile(state, left)
        flags += [self._leftover_ok(state, b) and pile for b in left]
        return _frac(flags)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible, matching=bool(rng.integers(0, 2)) or None)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.satisfied(state):
            return []
        P = _Planner(state)
        region = lambda c: _in_cell(c, self.CELL)  # noqa: E731
        P.unstack_all(region)
        matched, left = self._split(P.state)
        bowl_area = lambda c: not _bowl_free(P.state, c, 0.0)  # noqa: E731
        for b in sorted(P.state.blocks, key=lambda b: -_z(P.state, b)):
            w = relations(P.state).in_bowl(b)
            if w is not None and matched.get(b) != w:
                P.clear(b, bowl_area)
                P.park(b, lambda c: bowl_area(c) or region(c))
        for b, w in matched.items():
            if relations(P.state).in_bowl(b) != w:
                P.do(PutIn(block=b, bowl=w))
        if left:
            rel = relations(P.state)
            bases = [b for b in left if _on_table(P.state, b) and region(tuple(_xy(P.state, b))) and rel.above(b) is None]
            bases.sort(key=lambda b: _dist(_xy(P.state, b), CORNER_POINTS[self.CELL]))
            if bases:
                base = bases[0]
            else:
                base = left[0]
                cands = _near([c for c in _grid(-0.29, -0.11, -0.39, -0.21) if region(c)], CORNER_POINTS[self.CELL])
                if P.put_at_any(base, cands) is None:
                    return None
            top = base
            for b in left:
                if b == base:
                    continue
                if P.do(PutOn(block=b, target=top)):
                    top = b
        return _finish(self, P)


class R062(Intention):
    """Reading: with bowls ordered left to right, the first min(#blocks, #bowls) bowls hold
    exactly one block each and the remaining bowls are empty (no gap); extra blocks stay out."""

    name = "r062"
    description = "Fill the bowls from left to right, one block each, and don't skip any bowl."

    def _order(self, state: WorldState) -> list[str]:
        return sorted(state.bowls, key=lambda w: (_xy(state, w)[0], w))

    def _wanted(self, state: WorldState) -> dict[str, int]:
        order = self._order(state)
        k = min(len(order), len(state.blocks))
        return {w: int(i < k) for i, w in enumerate(order)}

    def satisfied(self, state: WorldState) -> bool:
        if not state.bowls or not state.blocks:
            return False
        return all(_count_in(state, w) == n for w, n in self._wanted(state).items())

    def score(self, state: WorldState) -> float:
        if not state.bowls:
            return 0.0
        return _frac([_count_in(state, w) == n for w, n in self._wanted(state).items()])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.bowls) >= 2 and len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible, n_bowls=2)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.bowls or not state.blocks:
            return None
        if self.satisfied(state):
            return []
        P = _Planner(state)
        wanted = self._wanted(state)
        order = self._order(state)
        bowl_region = lambda c: not _bowl_free(P.state, c, 0.0)  # noqa: E731
        # take extra blocks out of over-full bowls
        for w in order:
            for _ in range(6):
                inside = [b for b, x in relations(P.state).inside if x == w]
                if len(inside) <= wanted[w]:
                    break
                top = max(inside, key=lambda b: _z(P.state, b))
                short = [x for x in order if _count_in(P.state, x) < wanted[x] and x != w]
                if not (short and P.do(PutIn(block=top, bowl=short[0]))):
                    if not P.park(top, bowl_region):
                        return None
        # fill empty wanted bowls, left to right
        for w in order:
            if _count_in(P.state, w) >= wanted[w]:
                continue
            rel = relations(P.state)
            loose = [b for b in P.state.blocks if rel.in_bowl(b) is None]
            loose.sort(key=lambda b: (rel.above(b) is not None, -_z(P.state, b), _dist(_xy(P.state, b), _xy(P.state, w))))
            for b in loose:
                P.clear(b, bowl_region)
                if P.do(PutIn(block=b, bowl=w)):
                    break
        return _finish(self, P)


class R074(Intention):
    """Reading: every block's centre is in the middle cell of the 3×3 grid (|x| < 10 cm of the
    centre line, -0.6 < y < -0.4), i.e. at least 10 cm from every edge; bowls cannot move."""

    name = "r074"
    description = (
        "Nothing near the edges, please. The cat swipes anything within paw reach of the edge, "
        "so keep everything clustered in the middle."
    )

    def _ok(self, state: WorldState, b: str) -> bool:
        return _cell(state, b) == "middle"

    def satisfied(self, state: WorldState) -> bool:
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        cands = _near(_grid(-0.09, 0.09, -0.59, -0.41, 0.01), CENTRE)
        cands = [c for c in cands if _in_cell(c, "middle")]
        return _region_plan(self, state, self._ok, lambda s, b: cands, lambda c: _in_cell(c, "middle"))


class R079(Intention):
    """Reading: no block is in a bowl of its own colour, and every block that has a
    different-coloured bowl on the table sits in one (several per bowl allowed)."""

    name = "r079"
    description = (
        "Put blocks in bowls only when the colours clash. Contrast is nice. Never a red block in a red bowl."
    )

    def _ok(self, state: WorldState, b: str) -> bool:
        w = relations(state).in_bowl(b)
        if w is not None and _color(w) == _color(b):
            return False
        clash = [x for x in state.bowls if _color(x) != _color(b)]
        return not clash or w is not None

    def satisfied(self, state: WorldState) -> bool:
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return any(_color(w) != _color(b) for b in scene.blocks for w in scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.satisfied(state):
            return []
        P = _Planner(state)
        bowl_region = lambda c: not _bowl_free(P.state, c, 0.0)  # noqa: E731
        for _ in range(3):
            for b in sorted(P.state.blocks, key=lambda b: -_z(P.state, b)):
                if self._ok(P.state, b):
                    continue
                P.clear(b, bowl_region)
                clash = [x for x in P.state.bowls if _color(x) != _color(b)]
                clash.sort(key=lambda x: (_count_in(P.state, x), _dist(_xy(P.state, x), _xy(P.state, b))))
                if clash:
                    any(P.do(PutIn(block=b, bowl=x)) for x in clash)
                else:
                    P.park(b, bowl_region)
            if self.satisfied(P.state):
                break
        return _finish(self, P)


class R081(Intention):
    """Reading: the pink block sits on top of a stack (on another block, nothing on it), and
    no other stack exists whose top is not pink; a stack is made if there is none."""

    name = "r081"
    description = "Pink on top of whatever's stacked. Always pink on top, it's my accent colour."
    PINK = "pink block"

    def satisfied(self, state: WorldState) -> bool:
        if self.PINK not in state.positions:
            return False
        rel = relations(state)
        if rel.below(self.PINK) is None or rel.above(self.PINK) is not None:
            return False
        stack = {self.PINK}
        b = self.PINK
        while (b := rel.below(b)) is not None:
            stack.add(b)
        return all(a in stack for a, _ in rel.on)

    def score(self, state: WorldState) -> float:
        if self.PINK not in state.positions:
            return 0.0
        if self.satisfied(state):
            return 1.0
        rel = relations(state)
        return 0.5 if rel.below(self.PINK) is not None and rel.above(self.PINK) is None else 0.0

    def feasible(self, scene: Scene) -> bool:
        return self.PINK in scene.blocks and len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        P = _Planner(state)
        P.clear(self.PINK)
        rel = relations(P.state)

        def height(b: str) -> int:
            h, r = 1, relations(P.state)
            while (b := r.below(b)) is not None:
                h += 1
            return h

        if rel.below(self.PINK) is None or rel.above(self.PINK) is not None:
            tops = [b for b in P.state.blocks if b != self.PINK and rel.above(b) is None]
            tops.sort(key=lambda b: (-height(b), not _on_table(P.state, b), b))
            for t in tops:
                if P.do(PutOn(block=self.PINK, target=t)):
                    break
        # dismantle any other stack
        for _ in range(8):
            rel = relations(P.state)
            stack, b = {self.PINK}, self.PINK
            while (b := rel.below(b)) is not None:
                stack.add(b)
            others = [a for a, _ in rel.on if a not in stack]
            if not others:
                break
            top = max(others, key=lambda a: _z(P.state, a))
            if not P.park(top):
                break
        return _finish(self, P)


def _even(vals: list[float], tol: float) -> bool:
    gaps = np.diff(sorted(vals))
    return len(gaps) == 0 or (gaps.min() >= BLOCK_SIZE and gaps.max() - gaps.min() <= tol)


def _line_plan(
    intent: Intention,
    state: WorldState,
    axis: int,
    fixed_vals: list[float],
    lo: float,
    hi: float,
    centre: float,
    max_spacing: float,
) -> list[Skill] | None:
    """Put all blocks on an evenly spaced line: coordinate ``axis`` varies, the other coordinate
    is one of ``fixed_vals``; the line avoids the bowls."""
    if intent.satisfied(state):
        return []
    blocks = list(state.blocks)
    n = len(blocks)
    if n == 0:
        return None
    bowls = [_xy(state, w) for w in state.bowls]
    order = sorted(blocks, key=lambda b: (_xy(state, b)[axis], b))
    tried = 0
    for fixed in fixed_vals:
        spacings = [0.0] if n == 1 else list(np.arange(min(max_spacing, (hi - lo) / (n - 1)), 0.0549, -0.01))
        for s in spacings:
            length = s * (n - 1)
            starts = np.arange(lo, hi - length + 1e-9, 0.01)
            starts = sorted(starts, key=lambda a: abs(a + length / 2 - centre))
            for a in starts:
                pts = []
                for i in range(n):
                    v = round(float(a + i * s), 4)
                    pts.append((v, fixed) if axis == 0 else (fixed, v))
                if not all(all(_dist(p, c) >= BOWL_CLEAR + 0.003 for c in bowls) for p in pts):
                    continue
                P = _Planner(state)
                if P.achieve(dict(zip(order, pts))) and intent.satisfied(P.state):
                    return P.steps
                tried += 1
                if tried > 30:
                    return None
    return None


class R082(Intention):
    """Reading: every block rests on the table near the right edge (x ≥ 0.20), all at the same x
    (±1.25 cm), in a front-to-back column with equal spacing (gaps ≥ 4 cm, differing ≤ 2.5 cm)."""

    name = "r082"
    description = (
        "Align all the blocks along the right edge, front to back, evenly spaced. Like a column in a layout grid."
    )

    def _edge(self, state: WorldState, b: str) -> bool:
        return _on_table(state, b) and _xy(state, b)[0] >= 0.20

    def satisfied(self, state: WorldState) -> bool:
        bs = state.blocks
        if not bs or not all(self._edge(state, b) for b in bs):
            return False
        xs = [_xy(state, b)[0] for b in bs]
        ys = [_xy(state, b)[1] for b in bs]
        return max(xs) - min(xs) <= 0.025 and _even(ys, 0.025)

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        return 0.9 * _frac([self._edge(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        return _line_plan(self, state, 1, [0.27, 0.28, 0.26, 0.29, 0.25, 0.24, 0.23, 0.22, 0.21],
                          -0.77, -0.23, -0.5, 0.20)


def _pile_plan(intent: Intention, state: WorldState, groups: list[tuple[list[str], Callable, tuple]]) -> list[Skill] | None:
    """Each group (members, region predicate on xy, preferred point) becomes one pile in its region."""
    if intent.satisfied(state):
        return []
    P = _Planner(state)
    P.unstack_all()
    for members, region, pref in groups:
        if not members:
            continue
        rel = relations(P.state)
        bases = [b for b in members if _on_table(P.state, b) and region(tuple(_xy(P.state, b))) and rel.above(b) is None]
        bases.sort(key=lambda b: _dist(_xy(P.state, b), pref))
        if bases:
            base = bases[0]
        else:
            base = members[0]
            cands = _near([c for c in TABLE_GRID if region(c)], pref)
            if P.put_at_any(base, cands) is None:
                return None
        top = base
        for b in members:
            if b != base and P.do(PutOn(block=b, target=top)):
                top = b
    return _finish(intent, P)


class R085(Intention):
    """Reading: all warm-coloured blocks form one pile (only warm blocks) standing in the left
    half (x < 0), all cool ones one pile in the right half (x > 0); a lone block is its own pile."""

    name = "r085"
    description = (
        "Group by temperature: warm colours stacked together in one pile on the left, "
        "cool colours in another pile on the right."
    )

    def _groups(self, state_or_scene) -> tuple[list[str], list[str]]:
        warm = [b for b in state_or_scene.blocks if _color(b) in WARM_COLORS]
        cool = [b for b in state_or_scene.blocks if _color(b) in COOL_COLORS]
        return warm, cool

    def _group_ok(self, state: WorldState, members: list[str], left: bool) -> list[bool]:
        if not members:
            return []
        pile = _single_pile(state, members)
        return [pile and ((_xy(state, b)[0] < 0) if left else (_xy(state, b)[0] > 0)) for b in members]

    def satisfied(self, state: WorldState) -> bool:
        warm, cool = self._groups(state)
        return all(self._group_ok(state, warm, True)) and all(self._group_ok(state, cool, False))

    def score(self, state: WorldState) -> float:
        warm, cool = self._groups(state)
        return _frac(self._group_ok(state, warm, True) + self._group_ok(state, cool, False))

    def feasible(self, scene: Scene) -> bool:
        warm, cool = self._groups(scene)
        return bool(warm) and bool(cool) and len(scene.blocks) >= 3

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible, n_blocks=3)

    def plan(self, state: WorldState) -> list[Skill] | None:
        warm, cool = self._groups(state)
        return _pile_plan(self, state, [
            (warm, lambda c: c[0] <= -0.05, (-0.2, -0.5)),
            (cool, lambda c: c[0] >= 0.05, (0.2, -0.5)),
        ])


class _AllInBowls(Intention):
    """Every block in some bowl, any bowl."""

    def _ok(self, state: WorldState, b: str) -> bool:
        return relations(state).in_bowl(b) is not None

    def satisfied(self, state: WorldState) -> bool:
        return bool(state.bowls) and all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not state.bowls:
            return None
        if self.satisfied(state):
            return []
        P = _Planner(state)
        for _ in range(3):
            for b in sorted(P.state.blocks, key=lambda b: -_z(P.state, b)):
                if self._ok(P.state, b):
                    continue
                bowls = sorted(P.state.bowls, key=lambda w: (_count_in(P.state, w), _dist(_xy(P.state, w), _xy(P.state, b))))
                any(P.do(PutIn(block=b, bowl=w)) for w in bowls)
            if self.satisfied(P.state):
                break
        return _finish(self, P)


class R086(_AllInBowls):
    """Reading: every block is inside some bowl (any bowl, stacking inside a bowl is fine)."""

    name = "r086"
    description = "Just put all the blocks in bowls so the cat has nothing to bat around. Honestly that's it."


class R091(_AllInBowls):
    """Reading: every block is inside some bowl (any bowl); no block rests loose on the table."""

    name = "r091"
    description = (
        "When I get in after a night shift I just want every block sitting in a bowl, doesn't matter "
        "which one. Nothing loose on the table, please."
    )


class _FrontRow(Intention):
    """All blocks on the table (none in bowls), in one left-to-right row near the front."""

    Y_MAX = -0.70
    EVEN_TOL: float | None = None
    ROWS = [-0.77, -0.76, -0.75, -0.74, -0.73, -0.72]

    def _placed(self, state: WorldState, b: str) -> bool:
        return _on_table(state, b) and _xy(state, b)[1] <= self.Y_MAX

    def satisfied(self, state: WorldState) -> bool:
        bs = state.blocks
        if not bs or not all(self._placed(state, b) for b in bs):
            return False
        ys = [_xy(state, b)[1] for b in bs]
        xs = sorted(_xy(state, b)[0] for b in bs)
        if max(ys) - min(ys) > 0.025:
            return False
        if self.EVEN_TOL is not None:
            return _even(xs, self.EVEN_TOL)
        return all(np.diff(xs) >= BLOCK_SIZE) if len(xs) > 1 else True

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        return 0.9 * _frac([self._placed(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        return _line_plan(self, state, 0, self.ROWS, -0.26, 0.26, 0.0, 0.20)


class R095(_FrontRow):
    """Reading: no block in any bowl; all blocks rest on the table in one straight row along the
    front edge (y ≤ -0.70, i.e. within 10 cm of it; y spread ≤ 2.5 cm, not touching)."""

    name = "r095"
    description = "Keep the bowls empty, love. Line the blocks up along the front edge instead."
    Y_MAX = -0.70
    EVEN_TOL = None


class R116(_FrontRow):
    """Reading: no block in any bowl; all blocks on the table in one straight, evenly spaced
    left-to-right row in the front third (y < -0.60, y spread ≤ 2.5 cm, gaps equal ±3 cm)."""

    name = "r116"
    description = "I want the blocks in a neat row across the front, lined up left to right, nothing in the bowls."
    Y_MAX = -0.60
    EVEN_TOL = 0.03
    ROWS = [-0.72, -0.70, -0.74, -0.68, -0.76, -0.66, -0.64, -0.77]


class _LeftHalf(Intention):
    """Every block wholly on the left half of the table (centre x ≤ -2 cm)."""

    X_MAX = -BLOCK_SIZE / 2

    def _ok(self, state: WorldState, b: str) -> bool:
        return _xy(state, b)[0] <= self.X_MAX + 1e-9

    def satisfied(self, state: WorldState) -> bool:
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        base = _grid(-0.28, -0.04, -0.78, -0.22, 0.02)

        def cands(s: WorldState, b: str) -> list[tuple[float, float]]:
            p = _xy(s, b)
            return sorted(base, key=lambda c: (abs(c[1] - p[1]) + 0.5 * abs(c[0] + 0.1), c))

        return _region_plan(self, state, self._ok, cands, lambda c: c[0] <= self.X_MAX)


class R103(_LeftHalf):
    """Reading: every block lies wholly in the left half of the table (centre x ≤ -2 cm); bowls
    cannot be moved and are ignored."""

    name = "r103"
    description = (
        "Nothing on the right half of the table. That's where my sister puts her mug down, "
        "so shift everything over to the left."
    )


class R114(_LeftHalf):
    """Reading: every block lies wholly in the left half of the table (centre x ≤ -2 cm), leaving
    the right half free of blocks; bowls cannot be moved and are ignored."""

    name = "r114"
    description = "Everything on the left side of the table. I'm right-handed and I need my right side free to work."


class R110(Intention):
    """Reading: every block's centre is in one of the four corner cells of the 3×3 grid (any
    corner, several per corner allowed), so the middle and the side cells hold no block."""

    name = "r110"
    description = (
        "Keep the middle of the table clear, that's my pass. All blocks to the corners, doesn't matter which corner."
    )

    def _ok(self, state: WorldState, b: str) -> bool:
        return _cell(state, b) in CORNERS

    def satisfied(self, state: WorldState) -> bool:
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        base = [c for c in TABLE_GRID if table_position_name(c) in CORNERS]
        deep = {c: min(_dist(c, p) for p in CORNER_POINTS.values()) for c in base}

        def cands(s: WorldState, b: str) -> list[tuple[float, float]]:
            p = _xy(s, b)
            return sorted(base, key=lambda c: (0.3 * _dist(c, p) + deep[c], c))

        return _region_plan(self, state, self._ok, cands, lambda c: table_position_name(c) in CORNERS)


class R152(Intention):
    """Reading: the green block is in the middle cell; every other block is near an edge (centre
    within 12 cm of a table edge) and the others are spread out (pairwise ≥ 12 cm apart)."""

    name = "r152"
    description = "Green block in the middle of the table, it's the pitch. Other blocks spread around the edges."
    GREEN = "green block"
    EDGE = 0.12
    SPREAD = 0.12

    @staticmethod
    def _edge_gap(p: Iterable[float]) -> float:
        x, y = tuple(p)[:2]
        return float(min(x - X_LEFT, X_RIGHT - x, y - Y_FRONT, Y_BACK - y))

    @staticmethod
    def _edge_pt(p: Iterable[float]) -> bool:
        return R152._edge_gap(p) <= R152.EDGE

    def _flags(self, state: WorldState) -> list[bool]:
        flags = [_cell(state, self.GREEN) == "middle"]
        others = [b for b in state.blocks if b != self.GREEN]
        for b in others:
            p = _xy(state, b)
            far = all(_dist(p, _xy(state, o)) >= self.SPREAD for o in others if o != b)
            flags.append(self._edge_pt(p) and far)
        return flags

    def satisfied(self, state: WorldState) -> bool:
        return self.GREEN in state.positions and all(self._flags(state))

    def score(self, state: WorldState) -> float:
        if self.GREEN not in state.positions:
            return 0.0
        return _frac(self._flags(state))

    def feasible(self, scene: Scene) -> bool:
        return self.GREEN in scene.blocks and len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        P = _Planner(state)
        mid = lambda c: _in_cell(c, "middle")  # noqa: E731
        ring = [c for c in _grid(-0.28, 0.28, -0.78, -0.22, 0.02) if self._edge_pt(c) and not mid(c)]
        for _ in range(2):
            # green to the middle
            if _cell(P.state, self.GREEN) != "middle":
                P.clear(self.GREEN, mid)
                cands = [c for c in _near(_grid(-0.09, 0.09, -0.59, -0.41, 0.01), CENTRE) if mid(c)]
                if P.put_at_any(self.GREEN, cands) is None:
                    for w in P.state.bowls:
                        if mid(tuple(_xy(P.state, w))) and P.do(PutIn(block=self.GREEN, bowl=w)):
                            break
            # others: keep those already well placed, move the rest to far-apart edge spots
            others = [b for b in P.state.blocks if b != self.GREEN]
            kept: list[str] = []
            for b in sorted(others, key=lambda b: (not self._edge_pt(_xy(P.state, b)), b)):
                p = _xy(P.state, b)
                if self._edge_pt(p) and relations(P.state).below(b) is None and all(
                    _dist(p, _xy(P.state, k)) >= self.SPREAD for k in kept
                ):
                    kept.append(b)
            for b in sorted(others, key=lambda b: -_z(P.state, b)):
                if b in kept:
                    continue
                P.clear(b)
                pending = [o for o in others if o not in kept and o != b]
                cands = [
                    c for c in ring
                    if all(_dist(c, _xy(P.state, k)) >= self.SPREAD + 0.01 for k in kept)
                    and all(_dist(c, _xy(P.state, o)) >= self.SPREAD + 0.01 for o in pending)
                ]
                p = _xy(P.state, b)
                cands.sort(key=lambda c: (_dist(c, p) + 1.5 * max(0.0, self._edge_gap(c) - 0.05), c))
                if P.put_at_any(b, cands) is not None:
                    kept.append(b)
            if self.satisfied(P.state):
                break
        return _finish(self, P)


__all__ = [
    "R012", "R018", "R025", "R030", "R048", "R050", "R062", "R074", "R079", "R081",
    "R082", "R085", "R086", "R091", "R095", "R103", "R110", "R114", "R116", "R152",
]
