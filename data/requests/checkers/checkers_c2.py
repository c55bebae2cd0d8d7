"""Checkers for requests r025, r079, r091, r116, r190, r251, r268, r327, r041, r135, r219, r305.

Each class judges a final table (``satisfied`` / ``score``), says whether the request can be shown
in a scene (``feasible``), samples such scenes, and plans skills that reach a satisfying table
under the symbolic world model (``activeintent.world.apply_skill``).

Conventions: x grows left to right; y grows from the front (near the person, y = -0.8) to the
back (y = -0.2). Judgements allow about a centimetre of settling noise; plans leave a margin of
at least that much to every threshold.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_INNER_RADIUS,
    BOWL_RADIUS,
    WARM_COLORS,
    PutAt,
    PutIn,
    PutOn,
    Scene,
    WorldState,
    apply_skill,
    relations,
    sample_scene,
)

# ----------------------------------------------------------------------------------------------
# geometry helpers
# ----------------------------------------------------------------------------------------------

H = BLOCK_SIZE / 2  # centre height of a block resting on the table
(X0, X1), (Y0, Y1) = BOUNDS
XLO, XHI, YLO, YHI = X0 + 0.02, X1 - 0.02, Y0 + 0.02, Y1 - 0.02  # block centre fully on the table
MIDDLE = (0.0, -0.5)
CLEARANCE = BLOCK_SIZE / 2 + 0.004  # world.predict: a placed block keeps footprint + 2.4 cm away
TABLE_TOL = 0.012  # a block this close to table height stands on the table
NEAR_BOWL = BOWL_INNER_RADIUS + 0.006  # a block centre this close to a bowl centre is in it


def _kind(n: str) -> str:
    return n.rsplit(" ", 1)[-1]


def _color(n: str) -> str:
    return n.split(" ", 1)[0]


def _rad(n: str) -> float:
    return BOWL_RADIUS if _kind(n) == "bowl" else H


def _xy(state: WorldState, n: str) -> tuple[float, float]:
    p = state.positions[n]
    return (float(p[0]), float(p[1]))


def _z(state: WorldState, n: str) -> float:
    return float(state.positions[n][2])


def _d(a: Iterable[float], b: Iterable[float]) -> float:
    a, b = tuple(a), tuple(b)
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _blocks(state: WorldState) -> list[str]:
    return [n for n in state.positions if _kind(n) == "block"]


def _bowls(state: WorldState) -> list[str]:
    return [n for n in state.positions if _kind(n) == "bowl"]


def _bowl_of(state: WorldState, b: str) -> str | None:
    """The bowl the block is in (also when stacked on a block in it), tolerant to ~1 cm."""
    best, bd = None, NEAR_BOWL
    bxy = _xy(state, b)
    if _z(state, b) >= 0.25:
        return None
    for w in _bowls(state):
        d = _d(bxy, _xy(state, w))
        if d < bd:
            best, bd = w, d
    return best


def _table_level(state: WorldState, b: str) -> bool:
    """Standing directly on the table (not stacked, not in a bowl)."""
    return abs(_z(state, b) - H) <= TABLE_TOL and _bowl_of(state, b) is None


def _gap(state: WorldState, a: str, b: str) -> float:
    """Horizontal gap between two footprints (negative when they overlap or are stacked)."""
    return _d(_xy(state, a), _xy(state, b)) - _rad(a) - _rad(b)


def _edge_dist(xy: tuple[float, float]) -> float:
    x, y = xy
    return min(x - X0, X1 - x, y - Y0, Y1 - y)


def _clusters(state: WorldState, blocks: list[str], tol: float = 0.025) -> list[list[str]]:
    """Blocks grouped by footprint (a stack is one group)."""
    parent = {b: b for b in blocks}

    def find(b: str) -> str:
        while parent[b] != b:
            parent[b] = parent[parent[b]]
            b = parent[b]
        return b

    for i, a in enumerate(blocks):
        for b in blocks[i + 1 :]:
            if _d(_xy(state, a), _xy(state, b)) < tol:
                parent[find(a)] = find(b)
    groups: dict[str, list[str]] = {}
    for b in blocks:
        groups.setdefault(find(b), []).append(b)
    return [sorted(g, key=lambda n: _z(state, n)) for g in groups.values()]


def _is_stack(state: WorldState, members: list[str], on_table: bool = True) -> bool:
    """A proper tower: bottom block on the table, each next one resting on the one below."""
    zs = [_z(state, b) for b in members]
    if on_table and not _table_level(state, members[0]):
        return False
    if not on_table and zs[0] > H + 0.02:
        return False
    return all(abs(zs[i + 1] - zs[i] - BLOCK_SIZE) <= 0.012 for i in range(len(zs) - 1))


def _centroid(state: WorldState, members: list[str]) -> tuple[float, float]:
    xs = [_xy(state, b)[0] for b in members]
    ys = [_xy(state, b)[1] for b in members]
    return (float(np.mean(xs)), float(np.mean(ys)))


_GRID = [
    (round(float(x), 4), round(float(y), 4))
    for x in np.arange(XLO, XHI + 1e-9, 0.01)
    for y in np.arange(YLO, YHI + 1e-9, 0.01)
]


def _sample(
    rng: np.random.Generator,
    nb: tuple[int, int],
    nw: Callable[[int], tuple[int, int]],
    pred: Callable[[Scene], bool] | None = None,
) -> Scene:
    """A world.sample_scene scene of 3-5 objects with nb blocks and nw(nb) bowls, meeting pred."""
    for _ in range(10000):
        n_b = int(rng.integers(nb[0], nb[1] + 1))
        lo, hi = nw(n_b)
        if hi < lo:
            continue
        n_w = int(rng.integers(lo, hi + 1))
        if not 3 <= n_b + n_w <= 5:
            continue
        scene = sample_scene(rng, n_blocks=n_b, n_bowls=n_w)
        if pred is None or pred(scene):
            return scene
    raise RuntimeError("could not sample a feasible scene")


# ----------------------------------------------------------------------------------------------
# planning helpers (exact symbolic states)
# ----------------------------------------------------------------------------------------------


class _Fail(Exception):
    pass


class _P:
    """A plan under construction: the predicted state and the steps so far."""

    def __init__(self, state: WorldState):
        self.s = state
        self.steps: list = []
        self.bounds = (XLO, XHI, YLO, YHI)  # where targets may lie (parking uses _GRID)

    def do(self, step) -> None:
        new, fail = apply_skill(self.s, step)
        if fail is not None:
            raise _Fail(fail.reason)
        self.s = new
        self.steps.append(step)

    def put_at(self, b: str, xy: tuple[float, float]) -> None:
        self.do(PutAt(block=b, position=(float(xy[0]), float(xy[1]))))

    def above(self, b: str) -> str | None:
        return relations(self.s).above(b)

    def tower(self, b: str) -> list[str]:
        out, t = [], self.above(b)
        while t is not None:
            out.append(t)
            t = self.above(t)
        return out

    def top(self, b: str) -> str:
        tw = self.tower(b)
        return tw[-1] if tw else b

    def at(self, b: str, xy: tuple[float, float]) -> bool:
        return _d(_xy(self.s, b), xy) < 0.004 and abs(_z(self.s, b) - H) < 0.004

    def occupants(self, xy: tuple[float, float], moving: str, margin: float = 0.0) -> list[str]:
        out = []
        for o, p in self.s.positions.items():
            if o == moving:
                continue
            if _kind(o) == "block" and p[2] > BLOCK_SIZE:
                continue
            if _d(p, xy) < _rad(o) + CLEARANCE + margin:
                out.append(o)
        return out

    def free(self, xy: tuple[float, float], moving: str, margin: float = 0.0) -> bool:
        x, y = xy
        xlo, xhi, ylo, yhi = self.bounds
        if not (xlo - 1e-9 <= x <= xhi + 1e-9 and ylo - 1e-9 <= y <= yhi + 1e-9):
            return False
        return not self.occupants(xy, moving, margin)

    def bowl_clear(self, xy: tuple[float, float], margin: float = 0.01) -> bool:
        x, y = xy
        if not (XLO - 1e-9 <= x <= XHI + 1e-9 and YLO - 1e-9 <= y <= YHI + 1e-9):
            return False
        return all(_d(xy, _xy(self.s, w)) >= BOWL_RADIUS + CLEARANCE + margin for w in _bowls(self.s))

    def find_spot(
        self,
        moving: str,
        pred: Callable[[tuple[float, float]], bool] | None = None,
        key: Callable[[tuple[float, float]], float] | None = None,
        margin: float = 0.01,
    ) -> tuple[float, float] | None:
        here = _xy(self.s, moving)
        key = key or (lambda p: _d(p, here))
        for p in sorted(_GRID, key=key):
            if (pred is None or pred(p)) and self.free(p, moving, margin):
                return p
        return None

    def park(
        self,
        b: str,
        pred: Callable[[tuple[float, float]], bool] | None = None,
        key: Callable[[tuple[float, float]], float] | None = None,
        margin: float = 0.01,
    ) -> None:
        """Move b (and first whatever is on it) to a free table spot meeting pred."""
        for t in reversed(self.tower(b)):
            self.park(t, pred, None, margin)
        spot = self.find_spot(b, pred, key, margin)
        if spot is None:
            spot = self.find_spot(b, pred, key, 0.0)
        if spot is None:
            raise _Fail(f"no free spot for the {b}")
        self.put_at(b, spot)

    def place_all(
        self,
        targets: dict[str, tuple[float, float]],
        park_pred: Callable[[tuple[float, float]], bool] | None = None,
    ) -> None:
        """Put each block of ``targets`` on the table at its point, moving blockers aside."""
        tpts = list(targets.values())

        def away(p: tuple[float, float]) -> bool:
            return all(_d(p, t) >= 0.08 for t in tpts) and (park_pred is None or park_pred(p))

        for _ in range(80):
            pending = [b for b, t in targets.items() if not self.at(b, t)]
            if not pending:
                return
            moved = False
            for b in pending:
                if self.above(b) is None and self.free(targets[b], b):
                    self.put_at(b, targets[b])
                    moved = True
                    break
            if moved:
                continue
            blockers = [self.top(b) for b in pending if self.above(b) is not None]
            for b in pending:
                for o in self.occupants(targets[b], b):
                    if _kind(o) == "bowl":
                        raise _Fail(f"the {o} covers a target")
                    blockers.append(self.top(o))
            if not blockers:
                raise _Fail("stuck")
            c = blockers[0]
            spot = self.find_spot(c, away)
            if spot is None:
                raise _Fail(f"nowhere to park the {c}")
            self.put_at(c, spot)
        raise _Fail("too many steps")

    def build_stacks(self, bases: list[tuple[float, float]], sizes: list[int]) -> None:
        """Build towers of the given sizes at the given (free) bases from all blocks."""
        placed: set[str] = set()
        for base, size in zip(bases, sizes):
            prev = None
            for _ in range(size):
                cand = [b for b in _blocks(self.s) if b not in placed and self.above(b) is None]
                if not cand:
                    raise _Fail("no free block")
                b = min(cand, key=lambda n: _d(_xy(self.s, n), base))
                if prev is None:
                    self.put_at(b, base)
                else:
                    self.do(PutOn(block=b, target=prev))
                placed.add(b)
                prev = b


def _run(
    state: WorldState,
    satisfied: Callable[[WorldState], bool],
    body: Callable[[_P], None],
    done: Callable[[WorldState], bool] | None = None,
):
    """Plan with ``body``; nothing to do when the table is already ``done`` (default: satisfied)."""
    if (done or satisfied)(state):
        return []
    p = _P(state)
    try:
        body(p)
    except _Fail:
        return None
    return p.steps if satisfied(p.s) else None


# ----------------------------------------------------------------------------------------------
# rows of blocks (r116, r190, r327)
# ----------------------------------------------------------------------------------------------


def _row_slots(
    p: _P,
    n: int,
    ys: list[float],
    pitches: list[float],
    centres: list[float],
    uneven_ok: bool,
    ok: Callable[[list[tuple[float, float]]], bool] | None = None,
) -> list[tuple[float, float]] | None:
    for y in ys:
        for pitch in pitches:
            for c in centres:
                xs = [c + (i - (n - 1) / 2) * pitch for i in range(n)]
                pts = [(round(x, 4), y) for x in xs]
                if all(p.bowl_clear(q) for q in pts) and (ok is None or ok(pts)):
                    return pts
    if uneven_ok:
        for y in ys:
            cand = [round(float(x), 4) for x in np.arange(XLO, XHI + 1e-9, 0.005) if p.bowl_clear((x, y))]
            chosen: list[float] = []
            for x in sorted(cand, key=lambda v: abs(v - centres[0])):
                if all(abs(x - c) >= 0.06 for c in chosen):
                    chosen.append(x)
                if len(chosen) == n:
                    pts = [(x, y) for x in sorted(chosen)]
                    if ok is None or ok(pts):
                        return pts
                    break
    return None


def _row_flags(state: WorldState, band: Callable[[float], bool]) -> tuple[list[bool], list[str]]:
    """Per block: on the table, in the wanted band, on the common line, not overlapping in x."""
    blocks = _blocks(state)
    if not blocks:
        return [], []
    ys = [_xy(state, b)[1] for b in blocks]
    line = float(np.mean(ys))
    flags = []
    for b in blocks:
        x, y = _xy(state, b)
        sep = min((abs(x - _xy(state, o)[0]) for o in blocks if o != b), default=1.0)
        flags.append(_table_level(state, b) and band(y) and abs(y - line) <= 0.015 and sep >= 0.03)
    return flags, blocks


def _row_plan(p: _P, slots: list[tuple[float, float]] | None) -> None:
    if slots is None:
        raise _Fail("no room for a row")
    blocks = sorted(_blocks(p.s), key=lambda b: _xy(p.s, b)[0])
    p.place_all(dict(zip(blocks, slots)))


# ----------------------------------------------------------------------------------------------
# r025
# ----------------------------------------------------------------------------------------------


def _in_bl_cell(xy: tuple[float, float], tol: float = 0.0) -> bool:
    """In the bottom left corner (3x3 grid cell x < -0.1, y < -0.6), grown by tol."""
    return xy[0] < -0.1 + tol and xy[1] < -0.6 + tol


class R025(Intention):
    name = "r025"
    description = (
        "Keep the red ones apart from the others, in the bottom left corner. "
        "Tomatoes always get their own bed in my garden."
    )

    def _flags(self, state: WorldState) -> dict[str, bool]:
        flags = {}
        reds = [b for b in _blocks(state) if _color(b) == "red"]
        nonred = [n for n in state.positions if _color(n) != "red"]
        for b in _blocks(state):
            bowl = _bowl_of(state, b)
            if _color(b) == "red":
                ok = _in_bl_cell(_xy(state, b), 0.01)
                ok = ok and (bowl is None or _color(bowl) == "red")
                ok = ok and all(_gap(state, b, o) >= 0.04 for o in nonred)
            else:
                ok = not _in_bl_cell(_xy(state, b), -0.01)
                ok = ok and (bowl is None or _color(bowl) != "red")
                ok = ok and all(_gap(state, b, r) >= 0.04 for r in reds)
            flags[b] = ok
        return flags

    def satisfied(self, state: WorldState) -> bool:
        if not any(_color(b) == "red" for b in _blocks(state)):
            return False
        return all(self._flags(state).values())

    def score(self, state: WorldState) -> float:
        f = self._flags(state)
        return sum(f.values()) / len(f) if f else 0.0

    def feasible(self, scene: Scene) -> bool:
        return "red block" in scene.blocks

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 3), lambda nb: (1, 2), self.feasible)

    def plan(self, state: WorldState):
        reds = [b for b in _blocks(state) if _color(b) == "red"]
        if not reds:
            return None

        def body(p: _P) -> None:
            red = reds[0]
            bowls = _bowls(p.s)
            red_bowl = next((w for w in bowls if _color(w) == "red"), None)

            def red_spot_ok(q: tuple[float, float], gap: float) -> bool:
                if not (q[0] <= -0.12 and q[1] <= -0.62):
                    return False
                for w in bowls:
                    need = BOWL_RADIUS + CLEARANCE + 0.005 if _color(w) == "red" else BOWL_RADIUS + H + gap
                    if _d(q, _xy(p.s, w)) < need:
                        return False
                return True

            corner = (-0.245, -0.745)
            pts = [q for q in _GRID if red_spot_ok(q, 0.065)] or [q for q in _GRID if red_spot_ok(q, 0.051)]
            target: tuple[float, float] | None = min(pts, key=lambda q: _d(q, corner)) if pts else None
            use_bowl = None
            if target is None:
                if red_bowl is not None and _in_bl_cell(_xy(p.s, red_bowl), -0.01):
                    use_bowl = red_bowl
                else:
                    raise _Fail("no room for the red block in the bottom left corner")
            home = target if target is not None else _xy(p.s, use_bowl)

            def bad(b: str) -> bool:
                xy = _xy(p.s, b)
                if _in_bl_cell(xy, 0.02):
                    return True
                if red_bowl is not None and _bowl_of(p.s, b) == red_bowl:
                    return True
                return _d(xy, home) < 2 * H + 0.07

            def good_park(q: tuple[float, float]) -> bool:
                return not _in_bl_cell(q, 0.03) and _d(q, home) >= 2 * H + 0.075

            def place_red() -> None:
                for t in reversed(p.tower(red)):
                    p.park(t, good_park)
                if use_bowl is not None:
                    if _bowl_of(p.s, red) != use_bowl:
                        p.do(PutIn(block=red, bowl=use_bowl))
                elif not p.at(red, target):
                    if p.free(target, red):
                        p.put_at(red, target)
                    else:  # out of the way for now; placed at the end
                        p.park(red, lambda q: _d(q, home) >= 0.1)

            for _ in range(20):
                others = [b for b in _blocks(p.s) if b != red and bad(b)]
                if not others:
                    break
                b = others[0]
                for t in reversed(p.tower(b)):
                    if t == red:
                        place_red()
                    else:
                        p.park(t, good_park)
                if red in p.tower(b):
                    continue
                p.park(b, good_park)
            place_red()
            if use_bowl is None and not p.at(red, target):
                p.put_at(red, target)

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r079
# ----------------------------------------------------------------------------------------------


def _clash(block: str, bowl: str) -> bool:
    """Contrasting colours: one warm, the other cool (so never the same colour)."""
    return (_color(block) in WARM_COLORS) != (_color(bowl) in WARM_COLORS)


class R079(Intention):
    name = "r079"
    description = (
        "Put blocks in bowls only when the colours clash. Contrast is nice. Never a red block in a red bowl."
    )

    def _flags(self, state: WorldState) -> dict[str, bool]:
        bowls = _bowls(state)
        out = {}
        for b in _blocks(state):
            w = _bowl_of(state, b)
            if w is not None:
                out[b] = _clash(b, w)
            else:
                out[b] = not any(_clash(b, v) for v in bowls)
        return out

    def satisfied(self, state: WorldState) -> bool:
        return all(self._flags(state).values())

    def score(self, state: WorldState) -> float:
        f = self._flags(state)
        return sum(f.values()) / len(f) if f else 1.0

    def feasible(self, scene: Scene) -> bool:
        return any(_clash(b, w) for b in scene.blocks for w in scene.bowls)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 3), lambda nb: (1, 2), self.feasible)

    def plan(self, state: WorldState):
        def body(p: _P) -> None:
            bowls = _bowls(p.s)

            def table_ok(q: tuple[float, float]) -> bool:
                return all(_d(q, _xy(p.s, w)) >= BOWL_RADIUS + CLEARANCE + 0.01 for w in bowls)

            # 1. empty each bowl down to its lowest wrong block
            for w in bowls:
                content = sorted([b for b in _blocks(p.s) if _bowl_of(p.s, b) == w], key=lambda n: _z(p.s, n))
                wrong = [i for i, b in enumerate(content) if not _clash(b, w)]
                if wrong:
                    for b in reversed(content[min(wrong) :]):
                        p.park(b, table_ok)
            # 2. put every block that has a contrasting bowl into one
            for _ in range(40):
                flags = self._flags(p.s)
                pending = [b for b, ok in flags.items() if not ok]
                if not pending:
                    return
                clear = [b for b in pending if p.above(b) is None]
                if clear:
                    b = clear[0]
                    cands = [w for w in bowls if _clash(b, w)]
                    if not cands:
                        p.park(b, table_ok)
                        continue
                    count = {w: sum(1 for o in _blocks(p.s) if _bowl_of(p.s, o) == w) for w in cands}
                    w = min(cands, key=lambda v: (count[v], _d(_xy(p.s, v), _xy(p.s, b))))
                    p.do(PutIn(block=b, bowl=w))
                else:
                    p.park(p.top(pending[0]), table_ok)
            raise _Fail("too many steps")

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r091
# ----------------------------------------------------------------------------------------------


class R091(Intention):
    name = "r091"
    description = (
        "When I get in after a night shift I just want every block sitting in a bowl, doesn't matter "
        "which one. Nothing loose on the table, please."
    )

    def satisfied(self, state: WorldState) -> bool:
        return all(_bowl_of(state, b) is not None for b in _blocks(state))

    def score(self, state: WorldState) -> float:
        blocks = _blocks(state)
        return sum(_bowl_of(state, b) is not None for b in blocks) / len(blocks) if blocks else 1.0

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 3), lambda nb: (1, 2), self.feasible)

    def plan(self, state: WorldState):
        if not _bowls(state):
            return None

        def body(p: _P) -> None:
            bowls = _bowls(p.s)
            for _ in range(20):
                pending = [b for b in _blocks(p.s) if _bowl_of(p.s, b) is None]
                if not pending:
                    return
                b = next((b for b in pending if p.above(b) is None), None)
                if b is None:
                    raise _Fail("stuck")
                count = {w: sum(1 for o in _blocks(p.s) if _bowl_of(p.s, o) == w) for w in bowls}
                w = min(bowls, key=lambda v: (count[v] >= 2, _d(_xy(p.s, v), _xy(p.s, b))))
                p.do(PutIn(block=b, bowl=w))

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r116: row across the front, nothing in bowls
# ----------------------------------------------------------------------------------------------


class R116(Intention):
    name = "r116"
    description = "I want the blocks in a neat row across the front, lined up left to right, nothing in the bowls."

    @staticmethod
    def _band(y: float) -> bool:
        return y <= -0.59

    def satisfied(self, state: WorldState) -> bool:
        flags, _ = _row_flags(state, self._band)
        return bool(flags) and all(flags)

    def score(self, state: WorldState) -> float:
        flags, _ = _row_flags(state, self._band)
        return sum(flags) / len(flags) if flags else 0.0

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 4), lambda nb: (1, min(2, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        n = len(_blocks(state))
        if n < 1:
            return None
        ys = [-0.74, -0.76, -0.72, -0.70, -0.68, -0.66, -0.78, -0.64]
        pitches = [0.06, 0.07, 0.08, 0.09, 0.10, 0.12]
        centres = [0.0] + [s * k * 0.02 for k in range(1, 12) for s in (1, -1)]

        def body(p: _P) -> None:
            _row_plan(p, _row_slots(p, n, ys, pitches, centres, uneven_ok=True))

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r190: even row across the middle
# ----------------------------------------------------------------------------------------------


def _even(xs: list[float]) -> bool:
    xs = sorted(xs)
    gaps = np.diff(xs)
    if len(gaps) < 2:
        return True
    return float(gaps.max() - gaps.min()) <= max(0.03, 0.3 * float(gaps.mean()))


class R190(Intention):
    name = "r190"
    description = (
        "Just make it look tidy. All the blocks in a straight row across the middle, left to right, nice and even."
    )

    @staticmethod
    def _band(y: float) -> bool:
        return abs(y - MIDDLE[1]) <= 0.1

    def _global(self, state: WorldState) -> bool:
        xs = [_xy(state, b)[0] for b in _blocks(state)]
        if not xs:
            return False
        return _even(xs) and min(xs) <= 0.05 and max(xs) >= -0.05

    def satisfied(self, state: WorldState) -> bool:
        flags, _ = _row_flags(state, self._band)
        return bool(flags) and all(flags) and self._global(state)

    def score(self, state: WorldState) -> float:
        flags, _ = _row_flags(state, self._band)
        if not flags:
            return 0.0
        return sum(flags) / len(flags) * (1.0 if self._global(state) else 0.75)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 4), lambda nb: (max(0, 3 - nb), min(2, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        n = len(_blocks(state))
        if n < 1:
            return None
        ys = [-0.5, -0.49, -0.51, -0.48, -0.52, -0.47, -0.53, -0.46, -0.54, -0.45, -0.55,
              -0.44, -0.56, -0.43, -0.57, -0.42, -0.58]
        pitches = [0.08, 0.07, 0.09, 0.06, 0.10, 0.11, 0.12, 0.14, 0.16, 0.18, 0.20, 0.22, 0.24]
        centres = [0.0] + [s * k * 0.01 for k in range(1, 5) for s in (1, -1)]

        def crosses(pts: list[tuple[float, float]]) -> bool:
            return pts[0][0] <= 0.04 and pts[-1][0] >= -0.04

        def body(p: _P) -> None:
            _row_plan(p, _row_slots(p, n, ys, pitches, centres, uneven_ok=False, ok=crosses))

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r251: green block dead centre, everything else at the edges
# ----------------------------------------------------------------------------------------------


class R251(Intention):
    name = "r251"
    description = "Green block dead centre, all by itself. Everything else out at the edges."

    def _flags(self, state: WorldState) -> dict[str, bool]:
        out = {}
        blocks = _blocks(state)
        for b in blocks:
            xy = _xy(state, b)
            if _color(b) == "green":
                out[b] = (
                    _d(xy, MIDDLE) <= 0.025
                    and _table_level(state, b)
                    and all(_d(xy, _xy(state, o)) >= 2 * H + 0.04 for o in blocks if o != b)
                )
            else:
                out[b] = _edge_dist(xy) <= 0.08
        return out

    def satisfied(self, state: WorldState) -> bool:
        f = self._flags(state)
        return "green block" in f and all(f.values())

    def score(self, state: WorldState) -> float:
        f = self._flags(state)
        return sum(f.values()) / len(f) if f else 0.0

    def feasible(self, scene: Scene) -> bool:
        return "green block" in scene.blocks

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 4), lambda nb: (max(0, 3 - nb), min(1, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        if "green block" not in state.positions:
            return None
        g = "green block"

        def body(p: _P) -> None:
            if not p.bowl_clear(MIDDLE, 0.0):
                raise _Fail("a bowl sits in the middle")

            def edge(q: tuple[float, float]) -> bool:
                return _edge_dist(q) <= 0.05

            def edge_key(b: str) -> Callable[[tuple[float, float]], float]:
                here = _xy(p.s, b)
                return lambda q: _d(q, here)

            for _ in range(20):
                pending = [b for b in _blocks(p.s) if b != g and _edge_dist(_xy(p.s, b)) > 0.065]
                if not pending:
                    break
                clear = [b for b in pending if p.above(b) is None]
                if clear:
                    b = clear[0]
                    p.park(b, edge, edge_key(b), margin=0.012)
                else:
                    t = p.top(pending[0])
                    if t == g:
                        if p.free(MIDDLE, g):
                            p.put_at(g, MIDDLE)
                        else:
                            p.park(g, lambda q: _d(q, MIDDLE) >= 0.12)
                    else:
                        p.park(t, edge, edge_key(t), margin=0.012)
            for t in reversed(p.tower(g)):
                p.park(t, edge, edge_key(t), margin=0.012)
            if not p.at(g, MIDDLE):
                p.put_at(g, MIDDLE)

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r268: one block directly in front of each bowl
# ----------------------------------------------------------------------------------------------

LABEL_DY = BOWL_RADIUS + H + 0.012  # PutNextTo(side="front") offset


def _label_zone(state: WorldState, w: str, b: str, grow: float = 0.0) -> bool:
    wx, wy = _xy(state, w)
    x, y = _xy(state, b)
    return abs(x - wx) <= 0.03 + grow and 0.075 - grow <= wy - y <= 0.135 + grow


class R268(Intention):
    name = "r268"
    description = (
        "Label everything, like at work: put one block directly in front of each bowl so I know which bowl is which."
    )

    def _labelled(self, state: WorldState) -> dict[str, bool]:
        out = {}
        for w in _bowls(state):
            inzone = [b for b in _blocks(state) if _label_zone(state, w, b)]
            out[w] = len(inzone) == 1 and _table_level(state, inzone[0])
        return out

    def satisfied(self, state: WorldState) -> bool:
        f = self._labelled(state)
        return bool(f) and all(f.values())

    def score(self, state: WorldState) -> float:
        f = self._labelled(state)
        return sum(f.values()) / len(f) if f else 0.0

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.bowls) <= len(scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (1, 4), lambda nb: (max(1, 3 - nb), min(2, nb, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        bowls = _bowls(state)
        blocks = _blocks(state)
        if not bowls or len(blocks) < len(bowls):
            return None

        def body(p: _P) -> None:
            spots = {}
            for w in bowls:
                wx, wy = _xy(p.s, w)
                # straight in front if there is room, else up to 2 cm aside / 2.5 cm nearer or farther
                cand = sorted(
                    ((round(wx + dx, 4), round(wy - LABEL_DY - dy, 4))
                     for dx in np.arange(-0.02, 0.0201, 0.005) for dy in np.arange(-0.01, 0.0251, 0.005)),
                    key=lambda q: _d(q, (wx, wy - LABEL_DY)),
                )
                cand = [
                    q for q in cand
                    if X0 - 0.02 <= q[0] <= X1 + 0.02 and Y0 - 0.02 <= q[1] <= Y1 + 0.02
                    and all(_d(q, _xy(p.s, v)) >= BOWL_RADIUS + CLEARANCE + 0.002 for v in bowls)
                ]
                if not cand:
                    raise _Fail("no room in front of the " + w)
                spots[w] = cand[0]
            # assign: a block of the bowl's colour first, then the nearest free block
            free = list(blocks)
            assign: dict[str, str] = {}
            for w in bowls:
                same = f"{_color(w)} block"
                if same in free:
                    assign[w] = same
                    free.remove(same)
            for w in sorted((w for w in bowls if w not in assign), key=lambda v: _xy(p.s, v)[0]):
                b = min(free, key=lambda n: _d(_xy(p.s, n), spots[w]))
                assign[w] = b
                free.remove(b)
            extras = free

            def park_ok(q: tuple[float, float]) -> bool:
                return all(_d(q, s) >= 0.09 for s in spots.values())

            # extras out of every label zone first
            for _ in range(10):
                bad = [
                    b for b in extras
                    if any(_label_zone(p.s, w, b, 0.015) or _d(_xy(p.s, b), spots[w]) < 0.06 for w in bowls)
                ]
                if not bad:
                    break
                p.park(bad[0], park_ok)
            targets = {assign[w]: spots[w] for w in bowls}
            p.bounds = (X0 - 0.02, X1 + 0.02, Y0 - 0.02, Y1 + 0.02)  # the robot's reach
            p.place_all(targets, park_ok)
            for w in bowls:  # nothing stacked on a label
                for t in reversed(p.tower(assign[w])):
                    p.park(t, park_ok)

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r327: straight line along the back edge
# ----------------------------------------------------------------------------------------------


class R327(Intention):
    name = "r327"
    description = "Line everything up square along the back edge. I like a straight line, nothing crooked."

    @staticmethod
    def _band(y: float) -> bool:
        return y >= -0.28

    def satisfied(self, state: WorldState) -> bool:
        flags, _ = _row_flags(state, self._band)
        return bool(flags) and all(flags)

    def score(self, state: WorldState) -> float:
        flags, _ = _row_flags(state, self._band)
        return sum(flags) / len(flags) if flags else 0.0

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 4), lambda nb: (1, min(2, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        n = len(_blocks(state))
        if n < 1:
            return None
        ys = [-0.23, -0.24, -0.22, -0.25, -0.26]
        pitches = [0.06, 0.07, 0.08, 0.09, 0.10, 0.12]
        centres = [0.0] + [s * k * 0.02 for k in range(1, 12) for s in (1, -1)]

        def body(p: _P) -> None:
            _row_plan(p, _row_slots(p, n, ys, pitches, centres, uneven_ok=True))

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r041: a block at each corner, extras in the middle
# ----------------------------------------------------------------------------------------------

CORNERS = {(-1, -1): (-0.3, -0.8), (1, -1): (0.3, -0.8), (-1, 1): (-0.3, -0.2), (1, 1): (0.3, -0.2)}


def _in_corner(xy: tuple[float, float], c: tuple[int, int], reach: float = 0.09) -> bool:
    cx, cy = CORNERS[c]
    return abs(xy[0] - cx) <= reach and abs(xy[1] - cy) <= reach


def _in_middle(xy: tuple[float, float], tol: float = 0.01) -> bool:
    return abs(xy[0]) <= 0.1 + tol and abs(xy[1] - MIDDLE[1]) <= 0.1 + tol


class R041(Intention):
    name = "r041"
    description = (
        "Put one block at each corner of the table, like column footings. Any extra blocks go in the middle."
    )

    def _parts(self, state: WorldState) -> tuple[int, int, int]:
        blocks = _blocks(state)
        good_corners = 0
        in_corners: set[str] = set()
        for c in CORNERS:
            inside = [b for b in blocks if _in_corner(_xy(state, b), c)]
            in_corners |= set(inside)
            if len(inside) == 1 and _table_level(state, inside[0]):
                good_corners += 1
        middle = sum(1 for b in blocks if b not in in_corners and _in_middle(_xy(state, b)))
        stray = len(blocks) - len(in_corners) - middle
        return good_corners, middle, stray

    def satisfied(self, state: WorldState) -> bool:
        corners, _, stray = self._parts(state)
        return corners == 4 and stray == 0

    def score(self, state: WorldState) -> float:
        n = len(_blocks(state))
        if n == 0:
            return 0.0
        corners, middle, _ = self._parts(state)
        return min(1.0, (corners + min(middle, max(0, n - 4))) / n)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 4

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (4, 5), lambda nb: (0, 5 - nb), self.feasible)

    def plan(self, state: WorldState):
        if len(_blocks(state)) < 4:
            return None

        def body(p: _P) -> None:
            blocks = _blocks(p.s)
            assign: dict[tuple[int, int], str] = {}
            targets: dict[str, tuple[float, float]] = {}
            # keep blocks already standing well inside a corner
            for c in CORNERS:
                here = [b for b in blocks if b not in targets and _in_corner(_xy(p.s, b), c, 0.075)
                        and abs(_z(p.s, b) - H) < 0.004 and _bowl_of(p.s, b) is None]
                if here:
                    b = here[0]
                    assign[c] = b
                    targets[b] = _xy(p.s, b)
            for c in CORNERS:
                if c in assign:
                    continue
                cx, cy = CORNERS[c]
                ideal = (cx - c[0] * 0.04, cy - c[1] * 0.04)
                cand = sorted((q for q in _GRID if _in_corner(q, c, 0.07) and p.bowl_clear(q, 0.005)),
                              key=lambda q: _d(q, ideal))
                if not cand:
                    raise _Fail("a corner is covered")
                spot = cand[0]
                b = min((b for b in blocks if b not in targets), key=lambda n: _d(_xy(p.s, n), spot))
                assign[c] = b
                targets[b] = spot

            def not_corner(q: tuple[float, float]) -> bool:
                return not any(_in_corner(q, c, 0.11) for c in CORNERS)

            p.place_all(targets, not_corner)
            extras = [b for b in blocks if b not in targets]
            for _ in range(10):
                pending = [b for b in extras if not _in_middle(_xy(p.s, b), -0.02)
                           or any(_in_corner(_xy(p.s, b), c) for c in CORNERS)]
                if not pending:
                    break
                b = next((b for b in pending if p.above(b) is None), None)
                if b is None:
                    raise _Fail("stuck")
                spot = p.find_spot(b, lambda q: _in_middle(q, -0.02), lambda q: _d(q, MIDDLE))
                if spot is not None:
                    p.put_at(b, spot)
                    continue
                mid_bowls = [w for w in _bowls(p.s) if _in_middle(_xy(p.s, w), -0.02)]
                if mid_bowls:
                    p.do(PutIn(block=b, bowl=mid_bowls[0]))
                    continue
                raise _Fail("no room in the middle")

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r135: two stacks, one behind the other; extra block on the front one
# ----------------------------------------------------------------------------------------------


class R135(Intention):
    name = "r135"
    description = (
        "I'd like the blocks split into two stacks of equal height, one behind the other. "
        "If there's an odd number, the extra one goes on the front stack."
    )

    @staticmethod
    def _want(n: int) -> tuple[int, int]:
        return (n + 1) // 2, n // 2  # front, back

    def _analyse(self, state: WorldState) -> tuple[bool, float]:
        blocks = _blocks(state)
        n = len(blocks)
        if n < 2:
            return False, 0.0
        groups = _clusters(state, blocks)
        stacks = sorted((g for g in groups if _is_stack(state, g)), key=len, reverse=True)
        if len(stacks) < 2:
            return False, (min(len(stacks[0]), (n + 1) // 2) / n if stacks else 0.0)
        a, b = stacks[0], stacks[1]
        front, back = sorted((a, b), key=lambda g: _centroid(state, g)[1])
        fx, fy = _centroid(state, front)
        bx, by = _centroid(state, back)
        want_f, want_b = self._want(n)
        behind = by - fy >= 0.035 and abs(bx - fx) <= 0.045
        counted = min(len(front), want_f) + min(len(back), want_b)
        ok = len(groups) == 2 and len(front) == want_f and len(back) == want_b and behind
        return ok, counted / n * (1.0 if behind else 0.5)

    def satisfied(self, state: WorldState) -> bool:
        return self._analyse(state)[0]

    def score(self, state: WorldState) -> float:
        ok, s = self._analyse(state)
        return 1.0 if ok else min(s, 0.99)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (3, 5), lambda nb: (0, min(2, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        n = len(_blocks(state))
        if n < 2:
            return None

        def body(p: _P) -> None:
            def spot_ok(r: tuple[float, float]) -> bool:
                return (XLO <= r[0] <= XHI and YLO <= r[1] <= YHI and p.bowl_clear(r)
                        and not [o for o in p.occupants(r, "", 0.012) if _kind(o) == "block"])

            def pair_ok(q: tuple[float, float]) -> bool:
                return spot_ok(q) and spot_ok((q[0], round(q[1] + 0.06, 4)))

            front = next((q for q in sorted(_GRID, key=lambda q: _d(q, (0.0, -0.53))) if pair_ok(q)), None)
            if front is None:
                raise _Fail("no room for two stacks")
            back = (front[0], round(front[1] + 0.06, 4))
            p.build_stacks([front, back], list(self._want(n)))

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r219: rising scale 1, 2, 3, ... from left to right
# ----------------------------------------------------------------------------------------------


def _scale(n: int) -> list[int]:
    sizes, k = [], 1
    while n > 0:
        sizes.append(min(k, n))
        n -= sizes[-1]
        k += 1
    return sizes


class R219(Intention):
    name = "r219"
    description = (
        "Arrange them like a rising scale: one block on its own on the left, then a stack of two, "
        "then a stack of three, as far as they go."
    )

    def _analyse(self, state: WorldState) -> tuple[bool, float]:
        blocks = _blocks(state)
        n = len(blocks)
        if n == 0:
            return False, 0.0
        want = _scale(n)
        groups = sorted(_clusters(state, blocks), key=lambda g: _centroid(state, g)[0])
        proper = [_is_stack(state, g) for g in groups]
        matched = sum(min(len(g), w) for g, w, ok in zip(groups, want, proper) if ok)
        xs = [_centroid(state, g)[0] for g in groups]
        ys = [_centroid(state, g)[1] for g in groups]
        apart = all(b - a >= 0.035 for a, b in zip(xs, xs[1:]))
        in_line = max(ys) - min(ys) <= 0.06
        ok = [len(g) for g in groups] == want and all(proper) and apart and in_line
        return ok, matched / n * (1.0 if in_line else 0.75)

    def satisfied(self, state: WorldState) -> bool:
        return self._analyse(state)[0]

    def score(self, state: WorldState) -> float:
        ok, s = self._analyse(state)
        return 1.0 if ok else min(s, 0.99)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 3

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (3, 5), lambda nb: (0, min(2, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        n = len(_blocks(state))
        if n < 1:
            return None
        sizes = _scale(n)
        k = len(sizes)
        pitch = 0.07

        def body(p: _P) -> None:
            def ok(q: tuple[float, float]) -> bool:
                pts = [(round(q[0] + i * pitch, 4), q[1]) for i in range(k)]
                return all(
                    XLO <= r[0] <= XHI and p.bowl_clear(r)
                    and not [o for o in p.occupants(r, "", 0.012) if _kind(o) == "block"]
                    for r in pts
                )

            centre0 = (-(k - 1) * pitch / 2, -0.5)
            start = next((q for q in sorted(_GRID, key=lambda q: _d(q, centre0)) if ok(q)), None)
            if start is None:
                raise _Fail("no room for the scale")
            bases = [(round(start[0] + i * pitch, 4), start[1]) for i in range(k)]
            p.build_stacks(bases, sizes)

        return _run(state, self.satisfied, body)


# ----------------------------------------------------------------------------------------------
# r305: short colour names left, long ones right
# ----------------------------------------------------------------------------------------------


def _short(name: str) -> bool:
    """Colour names of up to four letters (red, blue, pink, cyan, gray) are short; five or more long."""
    return len(_color(name)) <= 4


class R305(Intention):
    name = "r305"
    description = (
        "Sort them by whether the colour name is short or long, please. Short names like red and blue to "
        "the left, long ones like orange and purple to the right."
    )

    def _flags(self, state: WorldState, margin: float = 0.0) -> dict[str, bool]:
        return {
            b: (_xy(state, b)[0] < -margin) if _short(b) else (_xy(state, b)[0] > margin)
            for b in _blocks(state)
        }

    def satisfied(self, state: WorldState) -> bool:
        f = self._flags(state)
        return bool(f) and all(f.values())

    def score(self, state: WorldState) -> float:
        f = self._flags(state)
        return sum(f.values()) / len(f) if f else 0.0

    def feasible(self, scene: Scene) -> bool:
        return any(_short(b) for b in scene.blocks) and any(not _short(b) for b in scene.blocks)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, (2, 4), lambda nb: (max(0, 3 - nb), min(2, 5 - nb)), self.feasible)

    def plan(self, state: WorldState):
        if not _blocks(state):
            return None

        def body(p: _P) -> None:
            def side_ok(b: str) -> Callable[[tuple[float, float]], bool]:
                return (lambda q: q[0] <= -0.05) if _short(b) else (lambda q: q[0] >= 0.05)

            def key(b: str) -> Callable[[tuple[float, float]], float]:
                x, y = _xy(p.s, b)
                return lambda q: _d(q, (-x, y))

            for _ in range(30):
                flags = self._flags(p.s, margin=0.02)
                pending = [b for b, ok in flags.items() if not ok]
                if not pending:
                    return
                clear = [b for b in pending if p.above(b) is None]
                b = clear[0] if clear else p.top(pending[0])
                p.park(b, side_ok(b), key(b))
            raise _Fail("too many steps")

        return _run(state, self.satisfied, body, lambda st: all(self._flags(st, margin=0.02).values()))


CHECKERS = [R025, R079, R091, R116, R190, R251, R268, R327, R041, R135, R219, R305]
