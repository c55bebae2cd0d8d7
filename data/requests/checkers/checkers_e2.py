"""Checkers for the pass-3 translation check, writer e2: request text and the world's public API only."""

from __future__ import annotations

import itertools
import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOWL_RADIUS,
    COLORS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    SceneError,
    WorldState,
    apply_skill,
    relations,
    sample_scene,
    table_position_name,
)

# --------------------------------------------------------------------------------------------
# Geometry conventions (from the world module): x left(-) → right(+), y front/bottom(-0.8) →
# back/top(-0.2); table centre (0, -0.5). Blocks are 4 cm cubes, bowls have a 6.5 cm rim radius.
# --------------------------------------------------------------------------------------------

X_LO, X_HI = -0.27, 0.27  # block centres kept fully on the table
Y_LO, Y_HI = -0.77, -0.23
CENTRE = (0.0, -0.5)
BOWL_KEEP = BOWL_RADIUS + BLOCK_SIZE / 2 + 0.004 + 0.004  # clearance of a new block from a bowl
BLOCK_KEEP = BLOCK_SIZE + 0.004 + 0.006  # clearance of a new block from another block
_GX = np.round(np.arange(X_LO, X_HI + 1e-9, 0.01), 4)
_GY = np.round(np.arange(Y_LO, Y_HI + 1e-9, 0.01), 4)
GRID = np.array([(x, y) for y in _GY for x in _GX], dtype=float)


def col(name: str) -> str:
    return name.split(" ", 1)[0]


def kind(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


def scene_blocks(scene: Scene) -> list[str]:
    return [o for o in scene.objects if kind(o) == "block"]


def scene_bowls(scene: Scene) -> list[str]:
    return [o for o in scene.objects if kind(o) == "bowl"]


def luma(c: str) -> float:
    r, g, b = COLORS[c]
    return (0.299 * r + 0.587 * g + 0.114 * b) * 255


def xy(state: WorldState, n: str) -> tuple[float, float]:
    p = state.positions[n]
    return (p[0], p[1])


def dist(a, b) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def chain_from(rel, base: str) -> list[str]:
    seq = [base]
    while (a := rel.above(seq[-1])) is not None:
        seq.append(a)
    return seq


def base_of(rel, b: str) -> str:
    while (d := rel.below(b)) is not None:
        b = d
    return b


def chains(state: WorldState) -> list[list[str]]:
    """Every stack (a lone block is a stack of one), bottom → top."""
    rel = relations(state)
    return [chain_from(rel, b) for b in state.blocks if rel.below(b) is None]


def loose(state: WorldState, b: str, rel=None) -> bool:
    """Standing on the table on its own: not in a bowl, nothing under it, nothing on it."""
    rel = rel or relations(state)
    return b in rel.on_table and rel.below(b) is None and rel.above(b) is None


def on_table_base(state: WorldState, b: str, rel=None) -> bool:
    rel = rel or relations(state)
    return b in rel.on_table and rel.below(b) is None


def clear_of(state: WorldState, p, ignore=()) -> bool:
    for n, (ox, oy, _) in state.positions.items():
        if n in ignore:
            continue
        d = math.hypot(p[0] - ox, p[1] - oy)
        if d < (BOWL_KEEP if kind(n) == "bowl" else BLOCK_KEEP):
            return False
    return True


def on_table_xy(p) -> bool:
    return X_LO - 1e-9 <= p[0] <= X_HI + 1e-9 and Y_LO - 1e-9 <= p[1] <= Y_HI + 1e-9


def find_spot(state, pred=None, prefer=CENTRE, ignore=(), reserved=(), sep=0.06, pts=None):
    """The free point (grid, or ``pts``) nearest ``prefer`` that satisfies ``pred``."""
    P = GRID if pts is None else np.asarray(pts, dtype=float).reshape(-1, 2)
    if len(P) == 0:
        return None
    mask = np.ones(len(P), dtype=bool)
    for n, (ox, oy, _) in state.positions.items():
        if n in ignore:
            continue
        keep = BOWL_KEEP if kind(n) == "bowl" else BLOCK_KEEP
        mask &= np.hypot(P[:, 0] - ox, P[:, 1] - oy) >= keep
    for r in reserved:
        mask &= np.hypot(P[:, 0] - r[0], P[:, 1] - r[1]) >= sep
    idx = np.nonzero(mask)[0]
    if pts is None:
        idx = idx[np.argsort(np.hypot(P[idx, 0] - prefer[0], P[idx, 1] - prefer[1]), kind="stable")]
    for i in idx:
        p = (round(float(P[i, 0]), 4), round(float(P[i, 1]), 4))
        if pred is None or pred(p):
            return p
    return None


def find_row(state, n, pitch, ignore, y_cands, x_pref=0.0, x_lo=X_LO, x_hi=X_HI):
    """n points in a horizontal row (left → right), on the first y of ``y_cands`` where one fits."""
    for y in y_cands:
        best = None
        for xc in np.round(np.arange(-0.27, 0.2701, 0.005), 4):
            xs = [round(float(xc + (i - (n - 1) / 2) * pitch), 4) for i in range(n)]
            if xs[0] < x_lo - 1e-9 or xs[-1] > x_hi + 1e-9:
                continue
            if all(clear_of(state, (x, y), ignore) for x in xs):
                if best is None or abs(xc - x_pref) < best[0]:
                    best = (abs(xc - x_pref), xs)
        if best is not None:
            return [(x, round(float(y), 4)) for x in best[1]]
    return None


def in_row_order(state: WorldState, blocks: list[str], key, gap_min=0.04, gap_max=None, y_spread=None) -> bool:
    """Blocks sorted by x have non-decreasing key, distinct x (gap_min), optional contiguity/alignment."""
    if len(blocks) <= 1:
        return True
    bs = sorted(blocks, key=lambda b: xy(state, b)[0])
    for a, b in zip(bs, bs[1:]):
        gx = xy(state, b)[0] - xy(state, a)[0]
        if gx < gap_min or (gap_max is not None and dist(xy(state, a), xy(state, b)) > gap_max):
            return False
        if key(b) < key(a):
            return False
    if y_spread is not None:
        ys = [xy(state, b)[1] for b in bs]
        if max(ys) - min(ys) > y_spread:
            return False
    return True


# Front of a bowl: the zone a block occupies when set "in front of" it (towards y = -0.8).
FRONT_DX, FRONT_DY = 0.06, (0.07, 0.16)


def in_front_zone(state: WorldState, b: str, w: str, rel=None) -> bool:
    rel = rel or relations(state)
    if not on_table_base(state, b, rel):
        return False
    bx, by = xy(state, b)
    wx, wy = xy(state, w)
    return abs(bx - wx) <= FRONT_DX and FRONT_DY[0] <= wy - by <= FRONT_DY[1]


def near_front_zone(p, w_xy, m=0.03) -> bool:
    return abs(p[0] - w_xy[0]) <= FRONT_DX + m and FRONT_DY[0] - m <= w_xy[1] - p[1] <= FRONT_DY[1] + m


def front_spots(w_xy) -> list[tuple[float, float]]:
    out = []
    for dy in np.arange(0.073, 0.1551, 0.006):
        for dx in (0.0, 0.01, -0.01, 0.02, -0.02, 0.03, -0.03, 0.04, -0.04, 0.05, -0.05, 0.056, -0.056):
            p = (round(w_xy[0] + dx, 4), round(w_xy[1] - float(dy), 4))
            if -0.31 <= p[0] <= 0.31 and p[1] >= -0.81:
                out.append((abs(dx) + abs(dy - 0.097), p))
    return [p for _, p in sorted(out)]


class _Fail(Exception):
    pass


class _Run:
    """Executes skills through the world's apply_skill, with small helpers to clear and park."""

    def __init__(self, state: WorldState):
        self.s = state
        self.steps: list = []

    @property
    def rel(self):
        return relations(self.s)

    def xy(self, n):
        return xy(self.s, n)

    def z(self, n):
        return self.s.positions[n][2]

    def do(self, step):
        s2, fail = apply_skill(self.s, step)
        if fail is not None:
            raise _Fail(fail.reason)
        self.s = s2
        self.steps.append(step)
        if len(self.steps) > 80:
            raise _Fail("plan too long")

    def above_chain(self, b):
        rel, out = self.rel, []
        a = rel.above(b)
        while a is not None:
            out.append(a)
            a = rel.above(a)
        return out

    def park(self, b, pred=None, prefer=None, reserved=()):
        """Move b to a free table spot (satisfying pred(b, p)) near prefer (default: where it is)."""
        self.clear(b, pred, reserved)
        p = (lambda q: pred(b, q)) if pred is not None else None
        spot = find_spot(self.s, p, prefer or self.xy(b), ignore={b}, reserved=reserved)
        if spot is None:
            raise _Fail(f"no parking spot for {b}")
        self.do(PutAt(block=b, position=spot))

    def clear(self, b, pred=None, reserved=()):
        for t in reversed(self.above_chain(b)):
            self.park(t, pred, reserved=reserved)

    def flatten(self, pred=None, reserved=()):
        for _ in range(20):
            rel = self.rel
            stacked = [b for b in self.s.blocks if rel.below(b) is not None and rel.above(b) is None]
            if not stacked:
                return
            self.park(max(stacked, key=self.z), pred, reserved=reserved)
        raise _Fail("flatten")

    def put_in(self, b, w, pred=None):
        if self.rel.in_bowl(b) == w:
            return
        self.clear(b, pred)
        self.do(PutIn(block=b, bowl=w))

    def put_on(self, b, t, pred=None):
        if self.rel.below(b) == t:
            return
        self.clear(b, pred)
        self.clear(t, pred)
        self.do(PutOn(block=b, target=t))

    def at(self, b, t):
        p = self.s.positions[b]
        return abs(p[0] - t[0]) < 1e-6 and abs(p[1] - t[1]) < 1e-6 and self.rel.below(b) is None and b in self.rel.on_table

    def place_all(self, targets: dict, pred=None):
        """Put every block of ``targets`` at its (x, y) on the table, parking whatever is in the way."""
        reserved = list(targets.values())
        for _ in range(8 * len(targets) + 10):
            pending = [b for b in targets if not self.at(b, targets[b])]
            if not pending:
                return
            done = False
            for b in pending:
                if self.rel.above(b) is not None:
                    continue
                step = PutAt(block=b, position=tuple(targets[b]))
                s2, fail = apply_skill(self.s, step)
                if fail is None:
                    self.s = s2
                    self.steps.append(step)
                    done = True
                    break
            if done:
                continue
            b = pending[0]
            if self.rel.above(b) is not None:
                self.clear(b, pred, reserved)
                continue
            t = targets[b]
            blockers = []
            for n, (ox, oy, oz) in self.s.positions.items():
                if n == b:
                    continue
                r = BOWL_RADIUS if kind(n) == "bowl" else BLOCK_SIZE / 2
                if kind(n) == "block" and oz > BLOCK_SIZE:
                    continue
                if math.hypot(ox - t[0], oy - t[1]) < r + BLOCK_SIZE / 2 + 0.0045:
                    blockers.append(n)
            if not blockers or any(kind(n) == "bowl" for n in blockers):
                raise _Fail(f"cannot place {b} at {t}")
            blk = blockers[0]
            top = ([blk] + self.above_chain(blk))[-1]
            self.park(top, pred, reserved=reserved)
        raise _Fail("place_all did not converge")

    def stack(self, seq, base_xy=None, pred=None):
        """Build one stack seq[0] (bottom) … seq[-1] (top); base at base_xy or where it stands."""
        base = seq[0]
        if base_xy is not None:
            self.place_all({base: base_xy}, pred)
        else:
            rel = self.rel
            if not (base in rel.on_table and rel.below(base) is None):
                self.park(base, pred)
        self.clear(base, pred)
        for lo, hi in zip(seq, seq[1:]):
            self.put_on(hi, lo, pred)


class _Base(Intention):
    """Shared sampling / planning scaffolding."""

    n_blocks: int | tuple[int, int] = (2, 3)
    n_bowls: int | tuple[int, int] = (1, 2)
    matching: bool | None = None

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        for _ in range(5000):
            try:
                sc = sample_scene(rng, n_blocks=self.n_blocks, n_bowls=self.n_bowls, matching=self.matching)
            except (SceneError, ValueError):
                continue
            if 3 <= len(sc.objects) <= 5 and self.feasible(sc):
                return sc
        raise RuntimeError(f"{self.name}: could not sample a feasible scene")

    def _parts(self, state: WorldState) -> list[bool]:
        return []

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        parts = self._parts(state)
        if not parts:
            return 0.0
        return float(min(0.95, sum(parts) / len(parts)))

    def _plan(self, run: _Run) -> None:
        raise NotImplementedError

    def plan(self, state: WorldState):
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        run = _Run(state)
        try:
            self._plan(run)
        except _Fail:
            return None
        return run.steps if self.satisfied(run.s) else None


def matched_pairs(state_or_scene) -> list[tuple[str, str]]:
    objs = list(state_or_scene.positions) if isinstance(state_or_scene, WorldState) else list(state_or_scene.objects)
    return [(b, f"{col(b)} bowl") for b in objs if kind(b) == "block" and f"{col(b)} bowl" in objs]


# --------------------------------------------------------------------------------------------
# r071
# --------------------------------------------------------------------------------------------


def _back_mid(p, m=0.0) -> bool:
    return abs(p[0]) <= 0.1 - m and p[1] >= -0.3 + m


class R071(_Base):
    """Matched blocks go in their same-colour bowl; the unmatched ones form one stack whose base
    stands on the table in the middle third of the back edge (|x| <= 0.1, y >= -0.3); a lone
    unmatched block just stands there."""

    name = "r071"
    description = ("Sort the blocks into two groups: ones that have a bowl of the same colour go in that "
                   "bowl, ones that don't get stacked together in the middle of the back edge.")
    n_blocks, n_bowls = 3, (1, 2)

    def feasible(self, scene):
        bowls = {col(w) for w in scene_bowls(scene)}
        bl = scene_blocks(scene)
        return any(col(b) in bowls for b in bl) and any(col(b) not in bowls for b in bl)

    def _groups(self, state):
        bowls = {col(w) for w in state.bowls}
        m = [b for b in state.blocks if col(b) in bowls]
        u = [b for b in state.blocks if col(b) not in bowls]
        return m, u

    def _parts(self, state):
        rel = relations(state)
        m, u = self._groups(state)
        parts = [rel.in_bowl(b) == f"{col(b)} bowl" for b in m]
        for b in u:
            base = base_of(rel, b)
            parts.append(base in u and base in rel.on_table and _back_mid(xy(state, base)))
        return parts

    def satisfied(self, state):
        rel = relations(state)
        m, u = self._groups(state)
        if not all(rel.in_bowl(b) == f"{col(b)} bowl" for b in m):
            return False
        return self.satisfied_unmatched(state, u)

    def _plan(self, run):
        m, u = self._groups(run.s)
        if not self.satisfied_unmatched(run.s, u):
            run.flatten()
            spot = find_spot(run.s, lambda p: _back_mid(p, 0.02), prefer=(0.0, -0.24), ignore=set(u))
            if spot is None:
                raise _Fail("no back-middle spot")
            seq = sorted(u, key=lambda b: dist(run.xy(b), spot))
            run.stack(seq, spot)
        for b in sorted(m, key=run.z, reverse=True):
            run.put_in(b, f"{col(b)} bowl")

    def satisfied_unmatched(self, state, u):
        if not u:
            return True
        rel = relations(state)
        cs = [c for c in chains(state) if set(c) & set(u)]
        if len(cs) != 1 or set(cs[0]) != set(u):
            return False
        return cs[0][0] in rel.on_table and _back_mid(xy(state, cs[0][0]))


# --------------------------------------------------------------------------------------------
# r147
# --------------------------------------------------------------------------------------------


class R147(_Base):
    """Blue block directly on (and topmost on) the lightest other block by luma (yellow > pink > gray >
    cyan > orange > …); every remaining block in some bowl (any bowl; unconstrained if no bowl)."""

    name = "r147"
    description = ("Our kit's blue and white so blue block on top of whatever's the lightest coloured block. "
                   "Rest can go in a bowl.")
    n_blocks, n_bowls = 3, (1, 2)

    def feasible(self, scene):
        bl = scene_blocks(scene)
        return "blue block" in bl and len(bl) >= 2

    def _roles(self, state):
        others = [b for b in state.blocks if b != "blue block"]
        light = max(others, key=lambda b: luma(col(b)))
        rest = [b for b in others if b != light]
        return light, rest

    def _parts(self, state):
        rel = relations(state)
        light, rest = self._roles(state)
        parts = [rel.below("blue block") == light and rel.above("blue block") is None]
        if state.bowls:
            parts += [rel.in_bowl(b) is not None for b in rest]
        return parts

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        light, rest = self._roles(run.s)
        run.flatten()
        bowls = run.s.bowls
        if bowls and rest:
            for b in (light, "blue block"):
                if run.rel.in_bowl(b) is not None:
                    run.park(b)
            for b in rest:
                if run.rel.in_bowl(b) is None:
                    w = min(bowls, key=lambda w: dist(run.xy(w), run.xy(b)))
                    run.put_in(b, w)
        run.put_on("blue block", light)


# --------------------------------------------------------------------------------------------
# r159
# --------------------------------------------------------------------------------------------


class R159(_Base):
    """As many stacks of exactly three as the block count allows (n // 3), and no stack taller than
    three; leftover blocks may stand alone or as a pair."""

    name = "r159"
    description = ("I want stacks of three max, they keep falling otherwise. Make as many little towers of "
                   "three as you can.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 3

    def _parts(self, state):
        cs = chains(state)
        want = len(state.blocks) // 3
        got = sum(1 for c in cs if len(c) == 3)
        return [got >= i + 1 for i in range(want)] + [all(len(c) <= 3 for c in cs)]

    def satisfied(self, state):
        cs = chains(state)
        return all(len(c) <= 3 for c in cs) and sum(len(c) == 3 for c in cs) == len(state.blocks) // 3

    def _plan(self, run):
        run.flatten()
        bl = sorted(run.s.blocks, key=lambda b: run.xy(b)[0])
        for i in range(len(bl) // 3):
            a, b, c = bl[3 * i: 3 * i + 3]
            run.put_on(b, a)
            run.put_on(c, b)


# --------------------------------------------------------------------------------------------
# r045
# --------------------------------------------------------------------------------------------


def _in_mid_box(p, m=0.0) -> bool:
    return abs(p[0]) < 0.12 + m and -0.62 - m < p[1] < -0.38 + m


class R045(_Base):
    """No block may touch the middle cell of the 3x3 table grid (centre not within |x| < 0.12,
    -0.62 < y < -0.38); blocks elsewhere (any edge/corner region) count as pushed to the sides."""

    name = "r045"
    description = ("Nothing in the middle of the table. I need that space for my model, so push everything "
                   "to the sides.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 1

    def _parts(self, state):
        return [not _in_mid_box(xy(state, b)) for b in state.blocks]

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        for b in sorted(run.s.blocks, key=run.z, reverse=True):
            p = run.xy(b)
            if not _in_mid_box(p):
                continue
            side = 0.22 if p[0] >= 0 else -0.22
            spot = find_spot(run.s, lambda q: not _in_mid_box(q, 0.015), prefer=(side, p[1]), ignore={b})
            if spot is None:
                raise _Fail("no side spot")
            run.clear(b, lambda _b, q: not _in_mid_box(q, 0.015))
            run.do(PutAt(block=b, position=spot))


# --------------------------------------------------------------------------------------------
# rows / gradients
# --------------------------------------------------------------------------------------------

GRADIENT = ["red", "orange", "yellow", "green", "cyan", "blue", "purple", "pink"]
NEUTRALS = {"brown", "gray"}


class R073(_Base):
    """All blocks loose on the table in one straight left→right row (y spread <= 3 cm, neighbours
    4–12 cm apart) ordered red, orange, yellow, green, cyan, blue, purple, pink, then brown/gray
    (either order) at the right end."""

    name = "r073"
    description = ("Arrange the blocks in a single row left to right as a gradient: warm to cool. Red, orange, "
                   "yellow, green, cyan, blue, purple, pink. Neutrals last.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    @staticmethod
    def rank(b):
        c = col(b)
        return GRADIENT.index(c) if c in GRADIENT else len(GRADIENT)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 2 and len({self.rank(b) for b in scene_blocks(scene)}) >= 2

    def _parts(self, state):
        rel = relations(state)
        parts = [loose(state, b, rel) for b in state.blocks]
        parts.append(in_row_order(state, state.blocks, self.rank))
        return parts

    def satisfied(self, state):
        rel = relations(state)
        return all(loose(state, b, rel) for b in state.blocks) and in_row_order(
            state, state.blocks, self.rank, gap_min=0.04, gap_max=0.12, y_spread=0.03)

    def _plan(self, run):
        run.flatten()
        bl = sorted(run.s.blocks, key=lambda b: (self.rank(b), col(b)))
        ys = sorted(np.round(np.arange(-0.75, -0.2499, 0.01), 4), key=lambda y: abs(y + 0.5))
        row = find_row(run.s, len(bl), 0.06, set(bl), ys)
        if row is None:
            raise _Fail("no row")
        run.place_all(dict(zip(bl, row)))


class R237(_Base):
    """The red/orange/yellow/green/cyan/blue/purple/pink blocks that are present stand loose in one
    straight row along the back edge (y >= -0.3), ordered in that sequence left→right, neighbours
    4–12 cm apart; brown/gray are not listed, so they may be anywhere except inside that row."""

    name = "r237"
    description = ("gradient along the back edge, warm to cool: red orange yellow green cyan blue purple "
                   "pink. skip what's not there. vibes")
    n_blocks, n_bowls = (3, 4), (0, 1)

    @staticmethod
    def rank(b):
        return GRADIENT.index(col(b))

    def feasible(self, scene):
        return sum(col(b) in GRADIENT for b in scene_blocks(scene)) >= 2

    def _split(self, state):
        g = [b for b in state.blocks if col(b) in GRADIENT]
        n = [b for b in state.blocks if col(b) not in GRADIENT]
        return g, n

    def _parts(self, state):
        rel = relations(state)
        g, _ = self._split(state)
        parts = [loose(state, b, rel) and xy(state, b)[1] >= -0.3 for b in g]
        parts.append(in_row_order(state, g, self.rank))
        return parts

    def satisfied(self, state):
        rel = relations(state)
        g, n = self._split(state)
        if not all(loose(state, b, rel) and xy(state, b)[1] >= -0.3 for b in g):
            return False
        if not in_row_order(state, g, self.rank, gap_min=0.04, gap_max=0.12, y_spread=0.03):
            return False
        xs = [xy(state, b)[0] for b in g]
        for b in n:
            p = xy(state, b)
            if p[1] >= -0.32 and min(xs) - 0.03 <= p[0] <= max(xs) + 0.03:
                return False
        return True

    def _plan(self, run):
        g, n = self._split(run.s)
        run.flatten()
        for b in n:
            if run.xy(b)[1] >= -0.34:
                run.park(b, lambda _b, q: q[1] <= -0.38, prefer=(run.xy(b)[0], -0.42))
        bl = sorted(g, key=self.rank)
        ys = np.round(np.arange(-0.24, -0.2901, -0.005), 4)
        row = find_row(run.s, len(bl), 0.055, set(bl), ys)
        if row is None:
            raise _Fail("no back row")
        run.place_all(dict(zip(bl, row)), pred=lambda _b, q: q[1] <= -0.36)


# --------------------------------------------------------------------------------------------
# r072
# --------------------------------------------------------------------------------------------

FRONT_EDGE_Y = -0.7


class R072(_Base):
    """'Right at the front edge' = block centre within 10 cm of the front edge (y < -0.7); such blocks
    are set directly behind a nearby object (else just moved straight back); the final-state check is
    that no block is left at the front edge (whether others stayed put is not visible in a final state)."""

    name = "r072"
    description = ("Leave the table how you found it except move any block that's sitting right at the front "
                   "edge back a bit, behind something. My teenager's always elbowing stuff off.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 1 and len(scene.objects) >= 2

    def _parts(self, state):
        return [xy(state, b)[1] >= FRONT_EDGE_Y for b in state.blocks]

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        front = [b for b in run.s.blocks if run.xy(b)[1] < FRONT_EDGE_Y]
        for b in sorted(front, key=run.z, reverse=True):
            rel = run.rel
            anchors = [w for w in run.s.bowls]
            anchors += [o for o in run.s.blocks if o not in front and on_table_base(run.s, o, rel)]
            anchors = sorted((o for o in anchors if dist(run.xy(o), run.xy(b)) <= 0.25),
                             key=lambda o: dist(run.xy(o), run.xy(b)))
            ok = False
            for o in anchors:
                s2, fail = apply_skill(run.s, PutNextTo(block=b, target=o, side="behind"))
                if fail is None and s2.positions[b][1] >= FRONT_EDGE_Y + 0.01:
                    run.do(PutNextTo(block=b, target=o, side="behind"))
                    ok = True
                    break
            if not ok:
                p = run.xy(b)
                spot = find_spot(run.s, lambda q: q[1] >= -0.68, prefer=(p[0], -0.64), ignore={b})
                if spot is None:
                    raise _Fail("nowhere behind")
                run.do(PutAt(block=b, position=spot))


# --------------------------------------------------------------------------------------------
# in front of matching bowls: r088, r234, r016
# --------------------------------------------------------------------------------------------


class _FrontOfMatch(_Base):
    n_blocks, n_bowls, matching = (2, 3), (1, 2), True
    forbid_in_bowls = False

    def feasible(self, scene):
        return len(matched_pairs(scene)) >= 1

    def _parts(self, state):
        rel = relations(state)
        return [in_front_zone(state, b, w, rel) for b, w in matched_pairs(state)]

    def satisfied(self, state):
        rel = relations(state)
        pairs = matched_pairs(state)
        if not all(in_front_zone(state, b, w, rel) for b, w in pairs):
            return False
        for b in state.blocks:
            for mb, w in pairs:
                if b != mb and in_front_zone(state, b, w, rel):
                    return False
        if self.forbid_in_bowls and any(rel.in_bowl(b) is not None for b in state.blocks):
            return False
        return True

    def _plan(self, run):
        pairs = matched_pairs(run.s)
        wxy = [run.xy(w) for _, w in pairs]

        def away(_b, q):
            return not any(near_front_zone(q, p) for p in wxy)

        if self.forbid_in_bowls:
            for b in sorted(run.s.blocks, key=run.z, reverse=True):
                if run.rel.in_bowl(b) is not None:
                    run.park(b, away)
        movers = {b for b, _ in pairs}
        for b in run.s.blocks:
            if b in movers:
                continue
            rel = run.rel
            if any(in_front_zone(run.s, b, w, rel) for _, w in pairs):
                run.park(b, away)
        targets = {}
        for b, w in pairs:
            if in_front_zone(run.s, b, w):
                targets[b] = run.xy(b)
                continue
            spot = next((p for p in front_spots(run.xy(w))
                         if clear_of(run.s, p, movers) and all(dist(p, q) >= 0.05 for q in targets.values())), None)
            if spot is None:
                raise _Fail(f"no spot in front of {w}")
            targets[b] = spot
        run.place_all(targets, away)


class R088(_FrontOfMatch):
    """Each block whose colour has a bowl stands loose directly in front of that bowl (front = towards
    the near edge, within the bowl's width, 7–16 cm from its centre); no other block may sit in such a
    pair's front spot; unmatched blocks otherwise free."""

    name = "r088"
    description = ("Make a little row of blocks in front of each bowl that matches it, so the bowl and block "
                   "read as a pair.")


class R234(_FrontOfMatch):
    """Each block with a same-colour bowl stands loose directly in front of it (towards the near edge,
    within the bowl's width, 7–16 cm from its centre); only that block sits there; others free."""

    name = "r234"
    description = ("Each block in front of the bowl of its colour, where there is one, so I can see the two "
                   "together.")


class R016(_FrontOfMatch):
    """Each block with a same-colour bowl stands loose directly in front of it (towards the near edge,
    within the bowl's width, 7–16 cm from centre); no block may be inside any bowl; blocks without a
    matching bowl are otherwise free."""

    name = "r016"
    description = ("Put each block in front of a bowl of the same colour, not in it. I want the kids to do the "
                   "dropping in themselves.")
    forbid_in_bowls = True


# --------------------------------------------------------------------------------------------
# r138
# --------------------------------------------------------------------------------------------


def _stair_k(n):
    k = 0
    while (k + 1) * (k + 2) // 2 <= n:
        k += 1
    return k


class R138(_Base):
    """Columns of heights 1, 2, …, k (k as large as the blocks allow) standing on the table side by side
    in a left-right line (bases within 3 cm in y, neighbours 4–8 cm apart), rising in either direction;
    leftover blocks (too few for the next column) may be anywhere."""

    name = "r138"
    description = ("Make a staircase: one block on its own, then a stack of two next to it, then a stack of "
                   "three, as far as the blocks will go.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 3

    def _found(self, state):
        rel = relations(state)
        k = _stair_k(len(state.blocks))
        cs = [c for c in chains(state) if c[0] in rel.on_table]
        by_h = {h: [c for c in cs if len(c) == h] for h in range(1, k + 1)}
        best = 0
        if any(not by_h[h] for h in range(1, k + 1)):
            return False, sum(1 for h in by_h if by_h[h]) / k
        for combo in itertools.product(*(by_h[h] for h in range(1, k + 1))):
            bases = [xy(state, c[0]) for c in combo]
            ys = [p[1] for p in bases]
            if max(ys) - min(ys) > 0.03:
                continue
            xs = [p[0] for p in bases]
            for sgn in (1, -1):
                ok = all(0.04 <= sgn * (xs[i + 1] - xs[i]) <= 0.08 for i in range(k - 1))
                if ok:
                    return True, 1.0
            best = 0.5
        return False, best

    def _parts(self, state):
        ok, frac = self._found(state)
        return [frac >= 0.5, frac >= 1.0, ok]

    def satisfied(self, state):
        return self._found(state)[0]

    def _plan(self, run):
        run.flatten()
        k = _stair_k(len(run.s.blocks))
        t = k * (k + 1) // 2
        bl = sorted(run.s.blocks, key=lambda b: dist(run.xy(b), CENTRE))
        stair, _left = bl[:t], bl[t:]
        ys = sorted(np.round(np.arange(-0.75, -0.2499, 0.01), 4), key=lambda y: abs(y + 0.5))
        row = find_row(run.s, k, 0.055, set(stair), ys)
        if row is None:
            raise _Fail("no row")
        cols, i = [], 0
        for h in range(1, k + 1):
            cols.append(stair[i: i + h])
            i += h
        run.place_all({c[0]: p for c, p in zip(cols, row)})
        for c in cols:
            for lo, hi in zip(c, c[1:]):
                run.put_on(hi, lo)


# --------------------------------------------------------------------------------------------
# r215
# --------------------------------------------------------------------------------------------

_TL, _BR = (-0.25, -0.25), (0.25, -0.75)
_DIAG_L = dist(_TL, _BR)
_U = ((_BR[0] - _TL[0]) / _DIAG_L, (_BR[1] - _TL[1]) / _DIAG_L)
_N = (-_U[1], _U[0])


def _diag_coords(p):
    v = (p[0] - _TL[0], p[1] - _TL[1])
    return v[0] * _U[0] + v[1] * _U[1], v[0] * _N[0] + v[1] * _N[1]


class R215(_Base):
    """All blocks loose on the table on the top-left (-0.25,-0.25) → bottom-right (0.25,-0.75) diagonal
    (<= 4 cm off the line), at least 5 cm apart along it, the end blocks within 20 cm of each corner."""

    name = "r215"
    description = ("lol just line the blocks up diagonally from the top left corner to the bottom right corner. "
                   "I like diagonals.")
    n_blocks, n_bowls = 3, (0, 2)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 2

    def _parts(self, state):
        rel = relations(state)
        out = []
        for b in state.blocks:
            t, d = _diag_coords(xy(state, b))
            out.append(loose(state, b, rel) and abs(d) <= 0.04 and -0.04 <= t <= _DIAG_L + 0.04)
        return out

    def satisfied(self, state):
        if not all(self._parts(state)):
            return False
        ts = sorted(_diag_coords(xy(state, b))[0] for b in state.blocks)
        if any(b - a < 0.05 for a, b in zip(ts, ts[1:])):
            return False
        return ts[0] <= 0.2 and ts[-1] >= _DIAG_L - 0.2

    def _plan(self, run):
        run.flatten()
        bl = sorted(run.s.blocks, key=lambda b: _diag_coords(run.xy(b))[0])
        n = len(bl)
        ign = set(bl)
        pts, prev = [], None
        for i in range(n):
            ideal = _DIAG_L * i / (n - 1)
            lo = -0.02 if prev is None else prev + 0.06
            hi = _DIAG_L + 0.02 - (n - 1 - i) * 0.06
            ts = sorted(np.round(np.arange(lo, hi + 1e-9, 0.005), 4), key=lambda t: abs(t - ideal))
            got = None
            for t in ts:
                for d in (0.0, 0.015, -0.015, 0.03, -0.03):
                    p = (round(_TL[0] + t * _U[0] + d * _N[0], 4), round(_TL[1] + t * _U[1] + d * _N[1], 4))
                    if on_table_xy(p) and clear_of(run.s, p, ign):
                        got = (t, p)
                        break
                if got:
                    break
            if got is None:
                raise _Fail("diagonal blocked")
            prev = got[0]
            pts.append(got[1])
        run.place_all(dict(zip(bl, pts)))


# --------------------------------------------------------------------------------------------
# r334
# --------------------------------------------------------------------------------------------


class R334(_Base):
    """The orange block stands loose directly in front of the blue bowl (towards the near edge, within
    the bowl's width, 7–16 cm from its centre); other blocks unconstrained."""

    name = "r334"
    description = "Put the orange block in front of the blue bowl. Just a habit, it's how I start the day."
    n_blocks, n_bowls = (2, 3), (1, 2)

    def feasible(self, scene):
        return "orange block" in scene.objects and "blue bowl" in scene.objects

    def _parts(self, state):
        return [in_front_zone(state, "orange block", "blue bowl")]

    def satisfied(self, state):
        return in_front_zone(state, "orange block", "blue bowl")

    def _plan(self, run):
        w = run.xy("blue bowl")
        spot = next((p for p in front_spots(w) if clear_of(run.s, p, {"orange block"})), None)
        if spot is None:
            spot = next((p for p in front_spots(w) if clear_of(run.s, p, set(run.s.blocks))), None)
        if spot is None:
            raise _Fail("front of blue bowl blocked")
        run.place_all({"orange block": spot}, lambda _b, q: not near_front_zone(q, w))


# --------------------------------------------------------------------------------------------
# bowls by colour: r220, r092
# --------------------------------------------------------------------------------------------


class R220(_Base):
    """Every block whose colour has a bowl is in that bowl; blocks without a same-colour bowl must not
    be in any (wrong) bowl."""

    name = "r220"
    description = ("Please put each block in the bowl of its own colour, the way a good pupil puts each music "
                   "book back where it belongs.")
    n_blocks, n_bowls, matching = (2, 3), (1, 2), True

    def feasible(self, scene):
        return len(matched_pairs(scene)) >= 1

    def _parts(self, state):
        rel = relations(state)
        bowls = set(state.bowls)
        out = []
        for b in state.blocks:
            w = f"{col(b)} bowl"
            out.append(rel.in_bowl(b) == w if w in bowls else rel.in_bowl(b) is None)
        return out

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        for _ in range(30):
            bad = [b for b, ok in zip(run.s.blocks, self._parts(run.s)) if not ok]
            if not bad:
                return
            b = max(bad, key=run.z)
            w = f"{col(b)} bowl"
            if w in run.s.positions:
                run.put_in(b, w)
            else:
                run.park(b)
        raise _Fail("r220 loop")


def _mid(p, m=0.0) -> bool:
    return abs(p[0]) <= 0.1 - m and -0.6 + m <= p[1] <= -0.4 - m


class R092(_Base):
    """Blocks with a same-colour bowl go in it; every block without one stands (loose or stacked) outside
    bowls in the middle cell of the table (|x| <= 0.1, -0.6 <= y <= -0.4)."""

    name = "r092"
    description = ("Put each block in the bowl that's the same colour as it, if there is one. Any block "
                   "without a match can go in the middle of the table.")
    n_blocks, n_bowls = 3, (1, 2)

    def feasible(self, scene):
        return len(matched_pairs(scene)) >= 1

    def _parts(self, state):
        rel = relations(state)
        out = []
        for b in state.blocks:
            w = f"{col(b)} bowl"
            if w in state.positions:
                out.append(rel.in_bowl(b) == w)
            else:
                out.append(rel.in_bowl(b) is None and table_position_name(xy(state, b)) == "middle")
        return out

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        for _ in range(30):
            bad = [b for b, ok in zip(run.s.blocks, self._parts(run.s)) if not ok]
            if not bad:
                return
            b = max(bad, key=run.z)
            w = f"{col(b)} bowl"
            if w in run.s.positions:
                run.put_in(b, w)
                continue
            run.clear(b)
            spot = find_spot(run.s, lambda p: _mid(p, 0.02), prefer=CENTRE, ignore={b})
            if spot is not None:
                run.do(PutAt(block=b, position=spot))
                continue
            rel = run.rel
            hosts = [c for c in chains(run.s) if b not in c and c[0] in rel.on_table
                     and _mid(xy(run.s, c[0])) and all(f"{col(x)} bowl" not in run.s.positions for x in c)]
            if not hosts:
                raise _Fail("middle full")
            run.put_on(b, hosts[0][-1])
        raise _Fail("r092 loop")


# --------------------------------------------------------------------------------------------
# r294
# --------------------------------------------------------------------------------------------


class R294(_Base):
    """All blocks in a single stack with brown (if present) at the bottom, gray (if present) directly
    above it, the other blocks above those in any order."""

    name = "r294"
    description = ("One stack only, please, and the darkest colours at the bottom: brown, gray, then the rest "
                   "on top.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    def feasible(self, scene):
        bl = scene_blocks(scene)
        return len(bl) >= 2 and ("brown block" in bl or "gray block" in bl)

    def _head(self, state):
        return [b for b in ("brown block", "gray block") if b in state.positions]

    def _parts(self, state):
        cs = sorted(chains(state), key=len, reverse=True)
        head = self._head(state)
        big = cs[0]
        return [b in big for b in state.blocks] + [big[: len(head)] == head]

    def satisfied(self, state):
        cs = chains(state)
        head = self._head(state)
        return len(cs) == 1 and cs[0][: len(head)] == head

    def _plan(self, run):
        head = self._head(run.s)
        rest = sorted((b for b in run.s.blocks if b not in head), key=lambda b: luma(col(b)))
        run.stack(head + rest)


# --------------------------------------------------------------------------------------------
# r174, r351
# --------------------------------------------------------------------------------------------


class R174(_Base):
    """n // 2 bowls each hold exactly two blocks (one on the other); every other bowl is empty, so a
    leftover odd block stays out of the bowls."""

    name = "r174"
    description = "Group the blocks in pairs, one on top of another, and put the pairs in the bowls."
    n_blocks, n_bowls = (2, 3), (1, 2)

    def feasible(self, scene):
        nb = len(scene_blocks(scene))
        return nb >= 2 and len(scene_bowls(scene)) >= nb // 2

    def _contents(self, state):
        rel = relations(state)
        return {w: [b for b in state.blocks if rel.in_bowl(b) == w] for w in state.bowls}

    def _parts(self, state):
        cont = self._contents(state)
        pairs = sum(1 for c in cont.values() if len(c) == 2)
        want = len(state.blocks) // 2
        return [pairs >= i + 1 for i in range(want)] + [all(len(c) in (0, 2) for c in cont.values())]

    def satisfied(self, state):
        rel = relations(state)
        cont = self._contents(state)
        if not all(len(c) in (0, 2) for c in cont.values()):
            return False
        for c in cont.values():
            if len(c) == 2 and not (rel.below(c[0]) == c[1] or rel.below(c[1]) == c[0]):
                return False
        return sum(len(c) == 2 for c in cont.values()) == len(state.blocks) // 2

    def _plan(self, run):
        for b in sorted(run.s.blocks, key=run.z, reverse=True):
            if run.rel.in_bowl(b) is not None or run.rel.below(b) is not None:
                run.park(b)
        bowls = list(run.s.bowls)
        bl = list(run.s.blocks)
        for i in range(len(bl) // 2):
            w = bowls[i]
            pair = sorted(bl, key=lambda b: dist(run.xy(b), run.xy(w)))[:2]
            for b in pair:
                bl.remove(b)
                run.put_in(b, w)


class R351(_Base):
    """n // 2 two-block stacks (no stack taller than two) whose bases stand on the table along the front
    edge (y <= -0.7) in a neat line (bases within 3 cm in y); an odd leftover block may be anywhere."""

    name = "r351"
    description = ("Pair them up, one on top of another, and set the pairs along the front edge. Neat as a hem.")
    n_blocks, n_bowls = (3, 4), (0, 1)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 2

    def _parts(self, state):
        rel = relations(state)
        cs = chains(state)
        good = [c for c in cs if len(c) == 2 and c[0] in rel.on_table and xy(state, c[0])[1] <= -0.7]
        want = len(state.blocks) // 2
        return [len(good) >= i + 1 for i in range(want)] + [all(len(c) <= 2 for c in cs)]

    def satisfied(self, state):
        rel = relations(state)
        cs = chains(state)
        if any(len(c) > 2 for c in cs):
            return False
        pairs = [c for c in cs if len(c) == 2]
        if len(pairs) != len(state.blocks) // 2:
            return False
        if not all(c[0] in rel.on_table and xy(state, c[0])[1] <= -0.7 for c in pairs):
            return False
        ys = [xy(state, c[0])[1] for c in pairs]
        return max(ys) - min(ys) <= 0.03

    def _plan(self, run):
        run.flatten()
        bl = sorted(run.s.blocks, key=lambda b: run.xy(b)[0])
        m = len(bl) // 2
        pairs = [bl[2 * i: 2 * i + 2] for i in range(m)]
        extra = bl[2 * m:]
        bases = [p[0] for p in pairs] + extra
        ys = np.round(np.arange(-0.76, -0.7049, 0.005), 4)
        row = find_row(run.s, len(bases), 0.065, set(bl), ys)
        if row is None:
            if extra:
                bases = [p[0] for p in pairs]
                row = find_row(run.s, len(bases), 0.065, set(bl), ys)
            if row is None:
                raise _Fail("no front row")
        run.place_all(dict(zip(bases, row)), pred=lambda _b, q: q[1] >= -0.66)
        for lo, hi in pairs:
            run.put_on(hi, lo, pred=lambda _b, q: q[1] >= -0.66)


# --------------------------------------------------------------------------------------------
# r178
# --------------------------------------------------------------------------------------------


def _middle_bowl(state) -> str:
    return min(state.bowls, key=lambda w: dist(xy(state, w), CENTRE))


class R178(_Base):
    """'Middle bowl' = the bowl nearest the table centre. All blocks loose on the table on a contiguous
    arc around it: equal distance from its centre (spread <= 2 cm, radius 8.5–17 cm), neighbours along
    the arc <= 8 cm apart."""

    name = "r178"
    description = ("Place the blocks in a neat arc around the middle bowl, one next to another, so they're all "
                   "the same distance from the centre.")
    n_blocks, n_bowls = 3, (1, 2)

    def feasible(self, scene):
        return len(scene_bowls(scene)) >= 1 and len(scene_blocks(scene)) >= 2

    def _parts(self, state):
        rel = relations(state)
        m = xy(state, _middle_bowl(state))
        return [loose(state, b, rel) and 0.085 <= dist(xy(state, b), m) <= 0.17 for b in state.blocks]

    def satisfied(self, state):
        if not all(self._parts(state)):
            return False
        m = xy(state, _middle_bowl(state))
        rs = [dist(xy(state, b), m) for b in state.blocks]
        if max(rs) - min(rs) > 0.02:
            return False
        pts = sorted((math.atan2(xy(state, b)[1] - m[1], xy(state, b)[0] - m[0]), b) for b in state.blocks)
        n = len(pts)
        if n < 2:
            return True
        gaps = [((pts[(i + 1) % n][0] - pts[i][0]) % (2 * math.pi), i) for i in range(n)]
        _, cut = max(gaps)
        order = [pts[(cut + 1 + j) % n][1] for j in range(n)]
        return all(dist(xy(state, a), xy(state, b)) <= 0.08 for a, b in zip(order, order[1:]))

    def _plan(self, run):
        run.flatten()
        w = _middle_bowl(run.s)
        m = run.xy(w)
        bl = list(run.s.blocks)
        n = len(bl)
        toward = math.atan2(CENTRE[1] - m[1], CENTRE[0] - m[0]) if dist(m, CENTRE) > 0.02 else -math.pi / 2
        phis = sorted(np.arange(0, 2 * math.pi, 0.05), key=lambda a: abs((a - toward + math.pi) % (2 * math.pi) - math.pi))
        for R in (0.10, 0.11, 0.12, 0.13):
            step = 2 * math.asin(0.03 / R)
            for phi in phis:
                angs = [phi + (i - (n - 1) / 2) * step for i in range(n)]
                pts = [(round(m[0] + R * math.cos(a), 4), round(m[1] + R * math.sin(a), 4)) for a in angs]
                if all(on_table_xy(p) and clear_of(run.s, p, set(bl)) for p in pts):
                    def rel_ang(b):
                        a = math.atan2(run.xy(b)[1] - m[1], run.xy(b)[0] - m[0])
                        return (a - angs[0] + math.pi) % (2 * math.pi)
                    order = sorted(bl, key=rel_ang)
                    run.place_all(dict(zip(order, pts)))
                    return
        raise _Fail("no arc")


# --------------------------------------------------------------------------------------------
# r097
# --------------------------------------------------------------------------------------------

_BR_CORNER = (0.3, -0.8)


class R097(_Base):
    """'Whatever block is in the bottom right corner' = the block (stack) standing nearest the table's
    bottom-right (front-right) corner; the yellow block must sit directly on top of that stack, with
    nothing on it. Without a yellow block there is nothing to do."""

    name = "r097"
    description = ("If there's a yellow block, put it on top of whatever block is in the bottom right corner. "
                   "That's my little reminder to take my vitamins.")
    n_blocks, n_bowls = (2, 3), (0, 2)

    def feasible(self, scene):
        bl = scene_blocks(scene)
        return "yellow block" in bl and len(bl) >= 2

    def _cands(self, state):
        """(base, top) of every stack not counting the yellow block and what is above it."""
        out = []
        for c in chains(state):
            sub = c[: c.index("yellow block")] if "yellow block" in c else c
            if sub:
                out.append((sub[0], sub[-1]))
        return out

    def satisfied(self, state):
        Y = "yellow block"
        if Y not in state.positions:
            return True
        rel = relations(state)
        below = rel.below(Y)
        if below is None or rel.above(Y) is not None:
            return False
        cands = self._cands(state)
        if not cands:
            return False
        best = min(dist(xy(state, b), _BR_CORNER) for b, _ in cands)
        return dist(xy(state, base_of(rel, Y)), _BR_CORNER) <= best + 1e-9

    def _parts(self, state):
        return [self.satisfied(state)]

    def _plan(self, run):
        Y = "yellow block"
        cands = self._cands(run.s)
        if not cands:
            run.clear(Y)
            cands = self._cands(run.s)
        base, top = min(cands, key=lambda bt: dist(run.xy(bt[0]), _BR_CORNER))
        dmin = dist(run.xy(base), _BR_CORNER)
        far = lambda _b, q: dist(q, _BR_CORNER) > dmin + 0.03  # noqa: E731
        run.clear(Y, far)
        run.clear(top, far)
        run.put_on(Y, top, far)


# --------------------------------------------------------------------------------------------
# r146
# --------------------------------------------------------------------------------------------


class R146(_Base):
    """All blocks loose on the table; the four front-most (all, if fewer) form a line along the front
    (y <= -0.6, y spread <= 3 cm, neighbours <= 12 cm apart); any others stand behind that line (>= 4 cm
    further back) and, if several, in a line of their own."""

    name = "r146"
    description = ("Line the blocks up like a back four along the front of the table, then the rest behind them "
                   "like midfield.")
    n_blocks, n_bowls = (4, 5), (0, 1)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= 4

    def _split(self, state):
        bl = sorted(state.blocks, key=lambda b: xy(state, b)[1])
        return bl[: min(4, len(bl))], bl[min(4, len(bl)):]

    def _parts(self, state):
        rel = relations(state)
        f, _ = self._split(state)
        return [loose(state, b, rel) for b in state.blocks] + [all(xy(state, b)[1] <= -0.6 for b in f)]

    def satisfied(self, state):
        rel = relations(state)
        if not all(loose(state, b, rel) for b in state.blocks):
            return False
        f, m = self._split(state)
        fy = [xy(state, b)[1] for b in f]
        if max(fy) > -0.6 or not in_row_order(state, f, lambda b: 0, 0.04, 0.12, 0.03):
            return False
        if any(xy(state, b)[1] < max(fy) + 0.04 for b in m):
            return False
        if len(m) >= 2 and not in_row_order(state, m, lambda b: 0, 0.04, 0.15, 0.03):
            return False
        return True

    def _plan(self, run):
        run.flatten()
        bl = sorted(run.s.blocks, key=lambda b: run.xy(b)[1])
        f, m = bl[:4], bl[4:]
        ign = set(bl)
        for yf in np.round(np.arange(-0.74, -0.6199, 0.01), 4):
            front = find_row(run.s, len(f), 0.07, ign, [yf])
            if front is None:
                continue
            if not m:
                back = []
            else:
                back = find_row(run.s, len(m), 0.07, ign, np.round(np.arange(yf + 0.1, yf + 0.2, 0.01), 4))
                if back is None:
                    continue
            f_sorted = sorted(f, key=lambda b: run.xy(b)[0])
            m_sorted = sorted(m, key=lambda b: run.xy(b)[0])
            run.place_all({**dict(zip(f_sorted, front)), **dict(zip(m_sorted, back))})
            return
        raise _Fail("no formation")


# --------------------------------------------------------------------------------------------
# r313
# --------------------------------------------------------------------------------------------


def _lane_of_color(c):
    if c in ("red", "pink"):
        return 0
    if c in ("blue", "cyan"):
        return 1
    return 2


def _lane_of_x(x):
    return 0 if x < -0.1 else (1 if x <= 0.1 else 2)


class R313(_Base):
    """Lanes are the left/middle/right thirds of the table (x < -0.1, |x| <= 0.1, x > 0.1): red and pink
    blocks in the left lane, blue and cyan in the middle, all others in the right (anywhere front-back,
    any support)."""

    name = "r313"
    description = ("Sort by lane: reds and pinks on the left, blues and cyans in the middle, everything else on "
                   "the right.")
    n_blocks, n_bowls = 3, (0, 2)

    def feasible(self, scene):
        return len({_lane_of_color(col(b)) for b in scene_blocks(scene)}) >= 2

    def _parts(self, state):
        return [_lane_of_x(xy(state, b)[0]) == _lane_of_color(col(b)) for b in state.blocks]

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        centres = {0: -0.2, 1: 0.0, 2: 0.2}

        def inlane(b, q):
            lane = _lane_of_color(col(b))
            return (q[0] <= -0.125) if lane == 0 else (abs(q[0]) <= 0.075 if lane == 1 else q[0] >= 0.125)

        for _ in range(30):
            bad = [b for b, ok in zip(run.s.blocks, self._parts(run.s)) if not ok]
            if not bad:
                return
            b = max(bad, key=run.z)
            run.clear(b, inlane)
            run.park(b, inlane, prefer=(centres[_lane_of_color(col(b))], run.xy(b)[1]))
        raise _Fail("r313 loop")


# --------------------------------------------------------------------------------------------
# r229, r233
# --------------------------------------------------------------------------------------------


def _dark_key(b):
    c = col(b)
    return {"brown": -2.0, "gray": -1.0}.get(c, luma(c))


def _dark_ok(a, b) -> bool:
    """May a stand left of b? Brown, then gray, then the rest by lightness (near-ties within 10 of 255
    in luma may go either way)."""
    ka, kb = _dark_key(a), _dark_key(b)
    if ka < 0 or kb < 0:
        return ka <= kb
    return kb >= ka - 10.0


class R229(_Base):
    """All blocks loose on the table in a rough row (y spread <= 5 cm), left→right (>= 4 cm apart in x)
    from dark to light: brown, gray, then the rest by lightness (luma; near-ties within 10/255 either way)."""

    name = "r229"
    description = ("Please sort them from dark to light, left to right. Brown and gray first, the bright ones "
                   "last.")
    n_blocks, n_bowls = 3, (0, 2)

    def feasible(self, scene):
        bl = scene_blocks(scene)
        return len(bl) >= 2 and any(not _dark_ok(b, a) for a in bl for b in bl if a != b)

    def _parts(self, state):
        rel = relations(state)
        bs = sorted(state.blocks, key=lambda b: xy(state, b)[0])
        parts = [loose(state, b, rel) for b in bs]
        parts += [_dark_ok(bs[i], bs[j]) for i in range(len(bs)) for j in range(i + 1, len(bs))]
        return parts

    def satisfied(self, state):
        if not all(self._parts(state)):
            return False
        xs = sorted(xy(state, b)[0] for b in state.blocks)
        ys = [xy(state, b)[1] for b in state.blocks]
        return all(b - a >= 0.04 for a, b in zip(xs, xs[1:])) and max(ys) - min(ys) <= 0.05

    def _plan(self, run):
        run.flatten()
        bl = sorted(run.s.blocks, key=_dark_key)
        ys = sorted(np.round(np.arange(-0.75, -0.2499, 0.01), 4), key=lambda y: abs(y + 0.5))
        row = find_row(run.s, len(bl), 0.06, set(bl), ys)
        if row is None:
            raise _Fail("no row")
        run.place_all(dict(zip(bl, row)))


RAINBOW = ["red", "orange", "yellow", "green", "cyan", "blue", "purple"]


class R233(_Base):
    """No block in a bowl, all loose on the table; the rainbow-coloured blocks (red, orange, yellow, green,
    cyan, blue, purple) in a rough row (y spread <= 5 cm) ordered left→right in that sequence (>= 4 cm
    apart in x); pink, brown and gray are not rainbow colours and may stand anywhere (loose)."""

    name = "r233"
    description = "Rainbow order, left to right, if you'd be so kind. Leave the bowls as they are."
    n_blocks, n_bowls = 3, (0, 2)

    def feasible(self, scene):
        return sum(col(b) in RAINBOW for b in scene_blocks(scene)) >= 2

    def _parts(self, state):
        rel = relations(state)
        rb = [b for b in state.blocks if col(b) in RAINBOW]
        parts = [loose(state, b, rel) for b in state.blocks]
        parts.append(in_row_order(state, rb, lambda b: RAINBOW.index(col(b)), y_spread=0.05))
        return parts

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        run.flatten()
        rb = sorted((b for b in run.s.blocks if col(b) in RAINBOW), key=lambda b: RAINBOW.index(col(b)))
        bl = rb + [b for b in run.s.blocks if col(b) not in RAINBOW]
        ys = sorted(np.round(np.arange(-0.75, -0.2499, 0.01), 4), key=lambda y: abs(y + 0.5))
        row = find_row(run.s, len(bl), 0.06, set(bl), ys)
        if row is None:
            raise _Fail("no row")
        run.place_all(dict(zip(bl, row)))


# --------------------------------------------------------------------------------------------
# r264
# --------------------------------------------------------------------------------------------


def _bowl_side(state):
    """(axis, sign) of the half of the table the bowls are on (axis with the larger offset)."""
    ws = [xy(state, w) for w in state.bowls]
    cx = sum(p[0] for p in ws) / len(ws) - CENTRE[0]
    cy = sum(p[1] for p in ws) / len(ws) - CENTRE[1]
    if abs(cx) >= abs(cy):
        return 0, (1.0 if cx >= 0 else -1.0)
    return 1, (1.0 if cy >= 0 else -1.0)


class R264(_Base):
    """'Other side' = the half of the table opposite the bowls' centroid (split left/right or front/back,
    whichever way the bowls are off-centre more); every block's centre lies in that half and at least
    5 cm clear of every bowl rim."""

    name = "r264"
    description = ("Keep the blocks away from the bowls, over on the other side of the table. I don't like "
                   "things mixing.")
    n_blocks, n_bowls = (2, 3), (1, 2)

    def feasible(self, scene):
        return len(scene_bowls(scene)) >= 1 and len(scene_blocks(scene)) >= 1

    def _ok(self, state, p, axis, sgn, m=0.0, d=0.135):
        if (p[axis] - CENTRE[axis]) * sgn > -m:
            return False
        return all(dist(p, xy(state, w)) >= d for w in state.bowls)

    def _parts(self, state):
        axis, sgn = _bowl_side(state)
        return [self._ok(state, xy(state, b), axis, sgn, 1e-9) for b in state.blocks]

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        axis, sgn = _bowl_side(run.s)
        pred = lambda _b, q: self._ok(run.s, q, axis, sgn, 0.03, 0.145)  # noqa: E731
        for b in sorted(run.s.blocks, key=run.z, reverse=True):
            if self._ok(run.s, run.xy(b), axis, sgn, 1e-9):
                continue
            p = list(run.xy(b))
            p[axis] = CENTRE[axis] - sgn * (0.2 if axis == 0 else 0.2)
            run.park(b, pred, prefer=tuple(p))


# --------------------------------------------------------------------------------------------
# r102, r223, r106
# --------------------------------------------------------------------------------------------


class R102(_Base):
    """Every bowl has exactly one block standing loose directly in front of it (towards the near edge,
    within its width, 7–16 cm from centre; any colour); every other block is inside some bowl."""

    name = "r102"
    description = ("I like one block in front of each bowl, like a little name tag. Any extra blocks can go in "
                   "the bowls.")
    n_blocks, n_bowls = (2, 3), (1, 2)

    def feasible(self, scene):
        return len(scene_blocks(scene)) >= len(scene_bowls(scene)) >= 1

    def _tags(self, state):
        rel = relations(state)
        return {w: [b for b in state.blocks if in_front_zone(state, b, w, rel)] for w in state.bowls}

    def _parts(self, state):
        rel = relations(state)
        tags = self._tags(state)
        tagged = {b for v in tags.values() for b in v}
        return [len(v) == 1 for v in tags.values()] + [
            rel.in_bowl(b) is not None for b in state.blocks if b not in tagged]

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        bowls = list(run.s.bowls)
        tags = self._tags(run.s)
        assign = {}
        for w in bowls:
            if tags[w]:
                assign[w] = sorted(tags[w], key=lambda b: col(b) != col(w))[0]
        free = [b for b in run.s.blocks if b not in assign.values()]
        for w in bowls:
            if w in assign:
                continue
            match = f"{col(w)} block"
            b = match if match in free else min(free, key=lambda b: dist(run.xy(b), run.xy(w)))
            assign[w] = b
            free.remove(b)
        wxy = [run.xy(w) for w in bowls]
        away = lambda _b, q: not any(near_front_zone(q, p) for p in wxy)  # noqa: E731
        movers = set(assign.values())
        targets = {}
        for w, b in assign.items():
            if in_front_zone(run.s, b, w):
                targets[b] = run.xy(b)
                continue
            spot = next((p for p in front_spots(run.xy(w)) if clear_of(run.s, p, set(run.s.blocks))
                         and all(dist(p, q) >= 0.05 for q in targets.values())), None)
            if spot is None:
                spot = next((p for p in front_spots(run.xy(w)) if clear_of(run.s, p, movers)), None)
            if spot is None:
                raise _Fail("no tag spot")
            targets[b] = spot
        run.place_all(targets, away)
        for b in sorted(free, key=run.z, reverse=True):
            if run.rel.in_bowl(b) is None:
                w = min(bowls, key=lambda w: dist(run.xy(w), run.xy(b)))
                run.put_in(b, w, away)


def _ring_spots(w_xy, prefer_angles_deg):
    out = []
    for a in prefer_angles_deg:
        for r in (0.097, 0.105, 0.113):
            t = math.radians(a)
            out.append((round(w_xy[0] + r * math.cos(t), 4), round(w_xy[1] + r * math.sin(t), 4)))
    return out


class R223(_Base):
    """One block per bowl (each bowl a seat for one); with more blocks than bowls every bowl holds exactly
    one and the extra blocks stand on the table next to (rim gap < 5 cm) the rightmost bowl; with fewer,
    each block alone in its own bowl."""

    name = "r223"
    description = ("The bowls are the choir stalls and the blocks are the singers. Every singer to a seat, and "
                   "if there aren't enough seats, the rest stand beside the last bowl on the right.")
    n_blocks, n_bowls = (2, 3), (1, 2)

    def feasible(self, scene):
        return len(scene_bowls(scene)) >= 1 and len(scene_blocks(scene)) >= 1

    def _parts(self, state):
        rel = relations(state)
        last = max(state.bowls, key=lambda w: xy(state, w)[0])
        cont = {w: [b for b in state.blocks if rel.in_bowl(b) == w] for w in state.bowls}
        parts = [len(c) <= 1 for c in cont.values()]
        nb, nw = len(state.blocks), len(state.bowls)
        if nb >= nw:
            parts += [len(c) == 1 for c in cont.values()]
        for b in state.blocks:
            if rel.in_bowl(b) is None:
                parts.append(nb > nw and on_table_base(state, b, rel) and rel.is_next_to(b, last))
        return parts

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        for b in sorted(run.s.blocks, key=run.z, reverse=True):
            if run.rel.below(b) is not None:
                run.park(b)
        bowls = sorted(run.s.bowls, key=lambda w: run.xy(w)[0])
        last = bowls[-1]
        for w in bowls:
            rel = run.rel
            if any(rel.in_bowl(b) == w for b in run.s.blocks):
                continue
            free = [b for b in run.s.blocks if rel.in_bowl(b) is None]
            if not free:
                break
            run.put_in(min(free, key=lambda b: dist(run.xy(b), run.xy(w))), w)
        rel = run.rel
        extras = [b for b in run.s.blocks if rel.in_bowl(b) is None]
        angles = [0, 30, -30, 60, -60, 90, -90, 120, -120, 150, -150, 180]
        targets = {}
        for b in extras:
            if on_table_base(run.s, b, rel) and rel.is_next_to(b, last):
                targets[b] = run.xy(b)
        for b in extras:
            if b in targets:
                continue
            spot = next((p for p in _ring_spots(run.xy(last), angles)
                         if X_LO - 0.02 <= p[0] <= X_HI + 0.02 and Y_LO - 0.02 <= p[1] <= Y_HI + 0.02
                         and clear_of(run.s, p, set(extras))
                         and all(dist(p, q) >= 0.05 for q in targets.values())), None)
            if spot is None:
                raise _Fail("no room beside the last bowl")
            targets[b] = spot
        run.place_all(targets)


class R106(_Base):
    """Cyan and blue blocks share one bowl; every other block is in a bowl too — in a different bowl from
    the cyan/blue one whenever there is more than one bowl."""

    name = "r106"
    description = ("Put the cyan and blue ones together in a bowl, it looks like a little hospital uniform. "
                   "The rest in any bowl you like.")
    n_blocks, n_bowls = 3, (1, 2)

    def feasible(self, scene):
        bl = scene_blocks(scene)
        return "cyan block" in bl and "blue block" in bl and len(scene_bowls(scene)) >= 1

    def _uniform_bowl(self, state):
        rel = relations(state)
        wc, wb = rel.in_bowl("cyan block"), rel.in_bowl("blue block")
        if wc is not None and wc == wb:
            return wc
        for w in ("blue bowl", "cyan bowl"):
            if w in state.positions:
                return w
        mid = tuple((a + b) / 2 for a, b in zip(xy(state, "cyan block"), xy(state, "blue block")))
        return min(state.bowls, key=lambda w: dist(xy(state, w), mid))

    def _acceptable(self, state, b, u):
        if b in ("cyan block", "blue block"):
            return {u}
        others = set(state.bowls) - {u}
        return others if others else {u}

    def _parts(self, state):
        rel = relations(state)
        wc, wb = rel.in_bowl("cyan block"), rel.in_bowl("blue block")
        u = wc if (wc is not None and wc == wb) else None
        parts = [u is not None]
        for b in state.blocks:
            if b in ("cyan block", "blue block"):
                continue
            w = rel.in_bowl(b)
            parts.append(w is not None and (w != u or len(state.bowls) == 1))
        return parts

    def satisfied(self, state):
        return all(self._parts(state))

    def _plan(self, run):
        u = self._uniform_bowl(run.s)
        for _ in range(30):
            rel = run.rel
            bad = [b for b in run.s.blocks if rel.in_bowl(b) not in self._acceptable(run.s, b, u)]
            if not bad:
                return
            b = max(bad, key=run.z)
            w = min(self._acceptable(run.s, b, u), key=lambda w: dist(run.xy(w), run.xy(b)))
            run.put_in(b, w)
        raise _Fail("r106 loop")


ALL = [R071, R147, R159, R045, R073, R072, R088, R138, R215, R334, R220, R294, R174, R351, R178, R097,
       R146, R313, R229, R264, R102, R223, R106, R233, R092, R234, R016, R237]
