"""Checkers for requests_b (r193 ... r359): one Intention class per request.

Conventions (metres): x left -> right in [-0.3, 0.3], y front -> back in [-0.8, -0.2].
"front" = small y (bottom side of the 3x3 grid), "back"/"behind" = large y (top side).
Thirds of the table follow activeintent.world.table_position_name (3x3 grid); region checks
allow ~1 cm of tolerance for physics settling.
"""

from __future__ import annotations

import itertools

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    COOL_COLORS,
    WARM_COLORS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    Skill,
    WorldState,
    apply_skill,
    relations,
    sample_scene,
)
from activeintent.world.scene import footprint_radius

X0, X1 = -0.3, 0.3
Y0, Y1 = -0.8, -0.2
TOL = 0.01
CELL_X = {"left": (-1.0, -0.1), "center": (-0.1, 0.1), "right": (0.1, 1.0)}
CELL_Y = {"bottom": (-2.0, -0.6), "mid": (-0.6, -0.4), "top": (-0.4, 1.0)}
CELLS = {
    "top left corner": ("left", "top"), "top side": ("center", "top"), "top right corner": ("right", "top"),
    "left side": ("left", "mid"), "middle": ("center", "mid"), "right side": ("right", "mid"),
    "bottom left corner": ("left", "bottom"), "bottom side": ("center", "bottom"),
    "bottom right corner": ("right", "bottom"),
}
CORNERS = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")
NEXT_GAP = BLOCK_SIZE / 2 + 0.065 + 0.012  # centre distance block <-> bowl after PutNextTo (0.097)
NB = 0.052  # centre distance block <-> block after PutNextTo


# ----------------------------------------------------------------------------- predicates

def color(n: str) -> str:
    return WorldState.color(n)


def xy(s: WorldState, n: str) -> np.ndarray:
    return s.pos(n)[:2]


def in_cell(p, name: str, tol: float = TOL) -> bool:
    cx, cy = CELLS[name]
    (xa, xb), (ya, yb) = CELL_X[cx], CELL_Y[cy]
    return xa - tol <= p[0] <= xb + tol and ya - tol <= p[1] <= yb + tol


def in_col(p, col: str, tol: float = TOL) -> bool:
    xa, xb = CELL_X[col]
    return xa - tol <= p[0] <= xb + tol


def in_row(p, row: str, tol: float = TOL) -> bool:
    ya, yb = CELL_Y[row]
    return ya - tol <= p[1] <= yb + tol


def flat_on_table(s: WorldState, b: str) -> bool:
    """Resting directly on the table (not in a bowl, not on another block)."""
    r = relations(s)
    return r.in_bowl(b) is None and r.below(b) is None and s.pos(b)[2] < BLOCK_SIZE / 2 + 0.012


def clear_top(s: WorldState, b: str) -> bool:
    return relations(s).above(b) is None


def match_bowl(s: WorldState, b: str) -> str | None:
    w = f"{color(b)} bowl"
    return w if w in s.positions else None


def scene_match_bowl(scene: Scene, b: str) -> str | None:
    w = f"{color(b)} bowl"
    return w if w in scene.objects else None


def tower(s: WorldState, b: str) -> list[str]:
    """The whole stack b belongs to, bottom first."""
    r = relations(s)
    base, seen = b, {b}
    while (d := r.below(base)) and d not in seen:
        seen.add(d)
        base = d
    out, cur = [base], base
    while (u := r.above(cur)) and u not in out:
        out.append(u)
        cur = u
    return out


def towers(s: WorldState) -> list[list[str]]:
    res, seen = [], set()
    for b in s.blocks:
        if b in seen:
            continue
        t = tower(s, b)
        seen.update(t)
        res.append(t)
    return res


def level(s: WorldState, b: str) -> int:
    t = tower(s, b)
    return t.index(b) + 1


def straight(s: WorldState, t: list[str], tol: float = 0.02) -> bool:
    base = xy(s, t[0])
    return all(np.hypot(*(xy(s, b) - base)) <= tol for b in t)


def rel_to_bowl(s: WorldState, b: str, w: str, side: str) -> bool:
    """b stands on the table just on ``side`` of bowl w (within next-to distance)."""
    if not flat_on_table(s, b):
        return False
    d = xy(s, b) - xy(s, w)
    lo, hi = 0.065 + 0.02 - 0.01, 0.065 + 0.02 + 0.05 + 0.01
    if side == "behind":
        return lo <= d[1] <= hi and abs(d[0]) <= 0.085
    if side == "front":
        return lo <= -d[1] <= hi and abs(d[0]) <= 0.085
    if side == "right":
        return lo <= d[0] <= hi and abs(d[1]) <= 0.045
    if side == "left":
        return lo <= -d[0] <= hi and abs(d[1]) <= 0.045
    raise ValueError(side)


def is_line(pts, tol: float = 0.025) -> bool:
    if len(pts) <= 1:
        return True
    a = np.array(pts)
    return float(np.ptp(a[:, 0])) <= tol or float(np.ptp(a[:, 1])) <= tol


def together(s: WorldState, a: str, b: str) -> bool:
    r = relations(s)
    if r.is_next_to(a, b) or tower(s, a) == tower(s, b):
        return True
    wa, wb = r.in_bowl(a), r.in_bowl(b)
    if wa is not None and wa == wb:
        return True
    return float(np.hypot(*(xy(s, a) - xy(s, b)))) <= 0.09


def connected(s: WorldState, blocks: list[str], dist: float = 0.095) -> bool:
    if len(blocks) <= 1:
        return True
    seen, todo = {blocks[0]}, [blocks[0]]
    while todo:
        a = todo.pop()
        for b in blocks:
            if b not in seen and float(np.hypot(*(xy(s, a) - xy(s, b)))) <= dist:
                seen.add(b)
                todo.append(b)
    return len(seen) == len(blocks)


# ----------------------------------------------------------------------------- planning

class PlanFail(Exception):
    pass


class Builder:
    def __init__(self, state: WorldState):
        self.s = state
        self.steps: list[Skill] = []

    def do(self, step: Skill, strict: bool = True) -> bool:
        ns, fail = apply_skill(self.s, step)
        if fail is not None:
            if strict:
                raise PlanFail(fail.reason)
            return False
        self.s = ns
        self.steps.append(step)
        return True


def is_free(s: WorldState, x: float, y: float, ignore=(), margin: float = 0.006, edge: float = 0.025) -> bool:
    if not (X0 + edge <= x <= X1 - edge and Y0 + edge <= y <= Y1 - edge):
        return False
    for o in s.names:
        if o in ignore:
            continue
        p = s.pos(o)
        if s.kind(o) == "block" and p[2] > BLOCK_SIZE:
            continue
        if np.hypot(p[0] - x, p[1] - y) < footprint_radius(o) + BLOCK_SIZE / 2 + 0.004 + margin:
            return False
    return True


_GX = np.round(np.arange(-0.275, 0.2751, 0.01), 4)
_GY = np.round(np.arange(-0.775, -0.2249, 0.01), 4)


def find_spot(s, pred, near, ignore=(), margin=0.006, avoid=()):
    """Free (x, y) with pred(x, y) true, nearest to ``near``; avoid: points to keep 6 cm from."""
    best, bd = None, 1e9
    for x in _GX:
        for y in _GY:
            if not pred((x, y)):
                continue
            d = (x - near[0]) ** 2 + (y - near[1]) ** 2
            if d >= bd:
                continue
            if any(np.hypot(x - a[0], y - a[1]) < 0.065 for a in avoid):
                continue
            if is_free(s, x, y, ignore, margin):
                best, bd = (float(x), float(y)), d
    return best


def clear_above(b: Builder, block: str, pred=lambda p: True) -> None:
    """Move whatever sits on ``block`` to free table spots (top first)."""
    t = tower(b.s, block)
    for u in reversed(t[t.index(block) + 1:]):
        spot = find_spot(b.s, pred, xy(b.s, u), ignore=(u,))
        if spot is None:
            raise PlanFail("no spot to unstack")
        b.do(PutAt(block=u, position=spot))


def flatten(b: Builder) -> None:
    """Put every block that is stacked or in a bowl on the table (top first)."""
    for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
        if not flat_on_table(b.s, blk):
            spot = find_spot(b.s, lambda p: True, xy(b.s, blk), ignore=(blk,))
            if spot is None:
                raise PlanFail("no spot to flatten")
            b.do(PutAt(block=blk, position=spot))


def move_to_region(b: Builder, blk: str, pred, near, avoid=(), allow_stack=True, allow_bowl=True) -> None:
    """Put blk somewhere in region pred: a free spot, else in a bowl there, else on a block there."""
    clear_above(b, blk)
    if flat_on_table(b.s, blk) and pred(xy(b.s, blk)):
        return
    spot = find_spot(b.s, pred, near, ignore=(blk,), avoid=avoid)
    if spot is not None:
        b.do(PutAt(block=blk, position=spot))
        return
    if allow_bowl:
        for w in b.s.bowls:
            if pred(xy(b.s, w)) and b.do(PutIn(block=blk, bowl=w), strict=False):
                return
    if allow_stack:
        for o in b.s.blocks:
            if o != blk and pred(xy(b.s, o)) and clear_top(b.s, o) and o not in tower(b.s, blk):
                if b.do(PutOn(block=blk, target=o), strict=False):
                    return
    raise PlanFail("region full")


def points_free(s, pts, movers, margin=0.004, edge=0.005) -> bool:
    for i, p in enumerate(pts):
        if not is_free(s, p[0], p[1], ignore=movers, margin=margin, edge=edge):
            return False
        for q in pts[:i]:
            if np.hypot(p[0] - q[0], p[1] - q[1]) < BLOCK_SIZE + 0.006:
                return False
    return True


def place_at_points(b: Builder, movers: list[str], pts: list[tuple[float, float]]) -> None:
    """Put movers[i] flat at pts[i]; movers in the way are parked first."""
    targets = dict(zip(movers, pts))
    for m in sorted(movers, key=lambda n: -b.s.pos(n)[2]):
        clear_above(b, m) if tower(b.s, m)[-1] not in movers else None
    # park movers that sit on someone else's target
    for m in sorted(movers, key=lambda n: -b.s.pos(n)[2]):
        here = xy(b.s, m)
        mine = targets[m]
        if np.hypot(*(here - mine)) < 0.005 and flat_on_table(b.s, m):
            continue
        if any(np.hypot(*(here - np.array(p))) < 0.05 for o, p in targets.items() if o != m):
            spot = find_spot(b.s, lambda p: True, here, ignore=(m,), avoid=list(targets.values()))
            if spot is None:
                raise PlanFail("no parking")
            if relations(b.s).above(m):
                raise PlanFail("mover covered")
            b.do(PutAt(block=m, position=spot))
    for m in sorted(movers, key=lambda n: -b.s.pos(n)[2]):
        mine = targets[m]
        if np.hypot(*(xy(b.s, m) - mine)) < 0.005 and flat_on_table(b.s, m):
            continue
        b.do(PutAt(block=m, position=(float(mine[0]), float(mine[1]))))


def line_candidates(n, region_pred, spacing=0.06, orient=("row", "col"), prefer=(0.0, -0.5)):
    """Straight lines of n points inside region_pred, roughly ordered by closeness to prefer."""
    out = []
    for o in orient:
        for a in np.arange(-0.27, 0.2701, 0.01):
            for c in np.arange(-0.77, -0.2299, 0.01):
                if o == "row":  # along x at y = c, starting at x = a
                    pts = [(float(a + i * spacing), float(c)) for i in range(n)]
                else:  # along y at x = a, starting at y = c
                    pts = [(float(a), float(c + i * spacing)) for i in range(n)]
                if all(X0 + 0.025 <= p[0] <= X1 - 0.025 and Y0 + 0.025 <= p[1] <= Y1 - 0.025 and region_pred(p)
                       for p in pts):
                    out.append(pts)
    cx, cy = prefer
    out.sort(key=lambda pts: np.hypot(np.mean([p[0] for p in pts]) - cx, np.mean([p[1] for p in pts]) - cy))
    return out


def place_line(b: Builder, movers: list[str], region_pred, spacing=0.06, orient=("row", "col"),
               prefer=(0.0, -0.5)) -> None:
    if not movers:
        return
    # keep movers already lined up in place if they already satisfy
    for pts in line_candidates(len(movers), region_pred, spacing, orient, prefer):
        if points_free(b.s, pts, movers):
            # assign movers to points by x then y order to reduce crossings
            order = sorted(movers, key=lambda m: (xy(b.s, m)[0], xy(b.s, m)[1]))
            place_at_points(b, order, pts)
            return
    raise PlanFail("no line")


def build_tower(b: Builder, blocks: list[str]) -> None:
    """Stack blocks[1:] on blocks[0] in order (blocks[0] stays where it is)."""
    top = blocks[0]
    for blk in blocks[1:]:
        if relations(b.s).below(blk) == top:
            top = blk
            continue
        clear_above(b, blk)
        b.do(PutOn(block=blk, target=top))
        top = blk


class Base(Intention):
    """Shared machinery: subclasses define _eval(state) -> (n_ok, n_total, global_ok), _plan(builder, v)."""

    n_variants = 3
    scene_blocks = (2, 4)
    scene_bowls = (1, 2)

    def _eval(self, state: WorldState) -> tuple[int, int, bool]:
        raise NotImplementedError

    def satisfied(self, state: WorldState) -> bool:
        ok, n, g = self._eval(state)
        return ok == n and g

    def score(self, state: WorldState) -> float:
        ok, n, g = self._eval(state)
        if n == 0:
            return 1.0 if g else 0.0
        if ok == n and not g:
            return (n - 0.5) / n
        return ok / n

    def showable(self, scene: Scene) -> bool:
        return self.feasible(scene)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        last = None
        for _ in range(2000):
            nb = int(rng.integers(self.scene_blocks[0], self.scene_blocks[1] + 1))
            nw = int(rng.integers(self.scene_bowls[0], self.scene_bowls[1] + 1))
            nw = max(0, min(nw, 5 - nb))
            if nb + nw < 3:
                nw = 3 - nb
            match = [True, False, None][int(rng.integers(3))]
            sc = sample_scene(rng, n_blocks=nb, n_bowls=nw, matching=match)
            last = sc
            if self.showable(sc):
                return sc
        return last

    def _plan(self, b: Builder, v: int) -> None:
        raise NotImplementedError

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.satisfied(state):
            return []
        for pre in (False, True):
            for v in range(self.n_variants):
                b = Builder(state)
                try:
                    if pre:
                        flatten(b)
                    self._plan(b, v)
                except PlanFail:
                    continue
                if self.satisfied(b.s):
                    return b.steps
        return None


PRIMARY = {"red", "yellow", "blue"}


# ----------------------------------------------------------------------------- requests

class R193(Base):
    name = "check-r193"
    description = "The yellow bowl holds the blue block if there is one and nothing else; with no blue block it stays empty."

    def feasible(self, scene):
        return "yellow bowl" in scene.objects and len(scene.blocks) >= 1

    def showable(self, scene):
        return self.feasible(scene) and "blue block" in scene.objects

    def _eval(self, s):
        r = relations(s)
        if "yellow bowl" not in s.positions:
            return 0, len(s.blocks), False
        ok = 0
        for b in s.blocks:
            inside = r.in_bowl(b) == "yellow bowl"
            ok += inside if b == "blue block" else not inside
        return ok, len(s.blocks), True

    def _plan(self, b, v):
        r = relations(b.s)
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            if blk != "blue block" and relations(b.s).in_bowl(blk) == "yellow bowl":
                move_to_region(b, blk, lambda p: True, xy(b.s, "yellow bowl"), allow_bowl=False, allow_stack=False)
        if "blue block" in b.s.positions and relations(b.s).in_bowl("blue block") != "yellow bowl":
            clear_above(b, "blue block")
            b.do(PutIn(block="blue block", bowl="yellow bowl"))
        del r


class R214(Base):
    # Order of pushing is not visible at the end; see comment below.
    name = "check-r214"
    description = "No block in the middle of the table; the blocks are split between the left and right sides, alternating so the two sides get equal shares."
    # "Alternating" is judged on the final table as an even split (counts differ by at most one);
    # the order in which blocks were pushed is not visible at the end.

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def _eval(self, s):
        left = [b for b in s.blocks if in_col(xy(s, b), "left")]
        right = [b for b in s.blocks if in_col(xy(s, b), "right")]
        cap = (len(s.blocks) + 1) // 2  # a side holding more than its share is not alternating
        ok = min(len(left), cap) + min(len(right), cap)
        return ok, len(s.blocks), abs(len(left) - len(right)) <= 1

    def _plan(self, b, v):
        blocks = sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2])
        n = len(blocks)
        nl = (n + (v % 2)) // 2
        # keep blocks already on a side where possible
        left = [x for x in blocks if in_col(xy(b.s, x), "left", -0.02)]
        right = [x for x in blocks if in_col(xy(b.s, x), "right", -0.02)]
        rest = [x for x in blocks if x not in left and x not in right]
        while len(left) > nl:
            rest.append(left.pop())
        while len(right) > n - nl:
            rest.append(right.pop())
        for x in rest:
            side = "left" if len(left) < nl else "right"
            (left if side == "left" else right).append(x)
            near = (-0.2, xy(b.s, x)[1]) if side == "left" else (0.2, xy(b.s, x)[1])
            move_to_region(b, x, lambda p, sd=side: in_col(p, sd, -0.025), near)


class R225(Base):
    name = "check-r225"
    description = "Yellow and orange blocks together on the left half, blue and cyan blocks together on the right half."
    # "left"/"right" = halves of the table; "together" = next to each other, stacked, in one bowl or
    # within 9 cm of each other.

    GROUPS = ((("yellow block", "orange block"), "L"), (("blue block", "cyan block"), "R"))

    def feasible(self, scene):
        return any(b in scene.objects for g, _ in self.GROUPS for b in g)

    def showable(self, scene):
        return self.feasible(scene) and len(scene.blocks) >= 2

    @staticmethod
    def _side_ok(p, side):
        return p[0] < -0.005 if side == "L" else p[0] > 0.005

    def _eval(self, s):
        ok, n, g = 0, 0, True
        for grp, side in self.GROUPS:
            present = [b for b in grp if b in s.positions]
            for b in present:
                n += 1
                ok += self._side_ok(xy(s, b), side)
            if len(present) == 2 and not together(s, *present):
                g = False
        return ok, n, g

    def _plan(self, b, v):
        for grp, side in self.GROUPS:
            present = [x for x in grp if x in b.s.positions]
            if not present:
                continue
            sx = -1 if side == "L" else 1
            region = (lambda p, sx=sx: sx * p[0] > 0.03)
            if len(present) == 1:
                move_to_region(b, present[0], region, (sx * 0.15, -0.5))
                continue
            if self._side_ok(xy(b.s, present[0]), side) and self._side_ok(xy(b.s, present[1]), side) and together(b.s, *present):
                continue
            prefer = (sx * (0.15 + 0.05 * v), -0.5 + 0.1 * (v - 1))
            place_line(b, present, region, spacing=NB, prefer=prefer)


class R228(Base):
    name = "check-r228"
    description = "The red block sits in the middle of the table with every other block close around it."
    # "around" = on the table within next-to distance (<= 9.5 cm centre to centre) of the red block.

    def feasible(self, scene):
        return "red block" in scene.objects

    def showable(self, scene):
        return self.feasible(scene) and len(scene.blocks) >= 2

    def _eval(self, s):
        if "red block" not in s.positions:
            return 0, len(s.blocks), False
        red = xy(s, "red block")
        ok = int(in_cell(red, "middle") and clear_top(s, "red block"))
        for b in s.blocks:
            if b != "red block":
                ok += flat_on_table(s, b) and np.hypot(*(xy(s, b) - red)) <= 0.095
        return ok, len(s.blocks), True

    def _plan(self, b, v):
        others = [x for x in b.s.blocks if x != "red block"]
        offs = [(NB, 0), (-NB, 0), (0, NB), (0, -NB), (NB, NB), (-NB, -NB), (NB, -NB), (-NB, NB)]
        movers = ["red block"] + others
        cands = []
        for x in np.arange(-0.08, 0.081, 0.01):
            for y in np.arange(-0.58, -0.419, 0.01):
                cands.append((float(x), float(y)))
        cands.sort(key=lambda p: np.hypot(p[0], p[1] + 0.5))
        for c in cands:
            pts = [c]
            avail = [(c[0] + dx, c[1] + dy) for dx, dy in offs]
            for p in avail:
                if len(pts) == len(movers):
                    break
                if points_free(b.s, pts + [p], movers):
                    pts.append(p)
            if len(pts) == len(movers) and points_free(b.s, pts, movers):
                place_at_points(b, movers, pts)
                return
        raise PlanFail("no room in middle")


class R231(Base):
    name = "check-r231"
    description = "The green block stands directly on top of the brown block; if either is missing, anything goes."

    def feasible(self, scene):
        return len(scene.blocks) >= 1  # the missing-block case is part of the rule

    def showable(self, scene):
        return "green block" in scene.objects and "brown block" in scene.objects

    def _eval(self, s):
        if "green block" not in s.positions or "brown block" not in s.positions:
            return len(s.blocks), len(s.blocks), True
        good = relations(s).below("green block") == "brown block"
        return 2 * good, 2, True

    def _plan(self, b, v):
        clear_above(b, "brown block")
        clear_above(b, "green block")
        if "brown block" in tower(b.s, "green block")[:tower(b.s, "green block").index("green block")]:
            pass
        if relations(b.s).below("brown block") == "green block":
            raise PlanFail("brown on green")  # flatten fallback handles it
        b.do(PutOn(block="green block", target="brown block"))


class R236(Base):
    name = "check-r236"
    description = "Every block is in a bowl whose colour differs from the block's colour."

    def feasible(self, scene):
        return bool(scene.blocks) and all(any(color(w) != color(b) for w in scene.bowls) for b in scene.blocks)

    def _ok(self, s, blk):
        w = relations(s).in_bowl(blk)
        return w is not None and color(w) != color(blk)

    def _eval(self, s):
        return sum(self._ok(s, x) for x in s.blocks), len(s.blocks), True

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            if self._ok(b.s, blk) and level(b.s, blk) == len(tower(b.s, blk)):
                continue
            if self._ok(b.s, blk):
                continue
            bowls = [w for w in b.s.bowls if color(w) != color(blk)]
            r = relations(b.s)
            bowls.sort(key=lambda w: (sum(1 for a, ww in r.inside if ww == w), (b.s.bowls.index(w) + v) % 3))
            clear_above(b, blk)
            b.do(PutIn(block=blk, bowl=bowls[0]))


class R244(Base):
    name = "check-r244"
    description = "Red, yellow and blue blocks go in bowls; every other block stays out of the bowls, lined up on the table in the left third."
    # "lined up" = the non-primary blocks lie on one straight row or column (within 2.5 cm).

    def feasible(self, scene):
        prim = [b for b in scene.blocks if color(b) in PRIMARY]
        return bool(scene.blocks) and (not prim or bool(scene.bowls))

    def showable(self, scene):
        return self.feasible(scene) and bool(scene.bowls)

    def _eval(self, s):
        r = relations(s)
        ok, rest = 0, []
        for b in s.blocks:
            if color(b) in PRIMARY:
                ok += r.in_bowl(b) is not None
            else:
                good = flat_on_table(s, b) and in_col(xy(s, b), "left")
                ok += good
                rest.append(xy(s, b))
        return ok, len(s.blocks), is_line(rest)

    def _plan(self, b, v):
        bowls = b.s.bowls
        for i, blk in enumerate(sorted([x for x in b.s.blocks if color(x) in PRIMARY], key=lambda n: -b.s.pos(n)[2])):
            if relations(b.s).in_bowl(blk) is None:
                clear_above(b, blk)
                b.do(PutIn(block=blk, bowl=bowls[(i + v) % len(bowls)]))
        rest = [x for x in b.s.blocks if color(x) not in PRIMARY]
        if len(rest) == 1:
            move_to_region(b, rest[0], lambda p: in_col(p, "left", -0.025), (-0.2, xy(b.s, rest[0])[1]),
                           allow_bowl=False, allow_stack=False)
        else:
            place_line(b, rest, lambda p: in_col(p, "left", -0.025), orient=("col", "row"), prefer=(-0.2, -0.5))


class R246(Base):
    name = "check-r246"
    description = "Each block stands just behind the bowl of its colour; a block with no such bowl stands just behind the gray bowl if there is one, otherwise anywhere."

    def feasible(self, scene):
        return any(scene_match_bowl(scene, b) for b in scene.blocks) or ("gray bowl" in scene.objects and bool(scene.blocks))

    def _target(self, s, blk):
        w = match_bowl(s, blk)
        if w is None and "gray bowl" in s.positions:
            w = "gray bowl"
        return w

    def _eval(self, s):
        ok = 0
        for blk in s.blocks:
            w = self._target(s, blk)
            ok += w is None or rel_to_bowl(s, blk, w, "behind")
        return ok, len(s.blocks), True

    def _plan(self, b, v):
        groups: dict[str, list[str]] = {}
        for blk in b.s.blocks:
            w = self._target(b.s, blk)
            if w:
                groups.setdefault(w, []).append(blk)
        movers = [x for g in groups.values() for x in g]
        pts = []
        for w, g in groups.items():
            wx, wy = xy(b.s, w)
            base = {1: [[0.0], [0.03], [-0.03]], 2: [[-0.026, 0.026], [0.0, NB], [-NB, 0.0]],
                    3: [[-NB, 0.0, NB]]}.get(len(g), [[-1.5 * NB, -0.5 * NB, 0.5 * NB, 1.5 * NB]])
            opt = base[v % len(base)]
            pts += [(wx + dx, wy + NEXT_GAP) for dx in opt]
        if not points_free(b.s, pts, movers):
            raise PlanFail("behind blocked")
        place_at_points(b, movers, pts)


class R249(Base):
    name = "check-r249"
    description = "All warm-coloured blocks form one tower and all cool-coloured blocks another, the two towers standing next to each other."

    def feasible(self, scene):
        w = [b for b in scene.blocks if color(b) in WARM_COLORS]
        c = [b for b in scene.blocks if color(b) in COOL_COLORS]
        return bool(w) and bool(c) and len(scene.blocks) >= 3

    def _eval(self, s):
        r = relations(s)
        ok, g, bases = 0, True, []
        for cls in (WARM_COLORS, COOL_COLORS):
            S = [b for b in s.blocks if color(b) in cls]
            if not S:
                continue
            best = max((t for t in towers(s)), key=lambda t: sum(color(x) in cls for x in t))
            pure = set(best) == set(S)
            ok += sum(color(x) in cls for x in best) if all(color(x) in cls for x in best) else 0
            if not (pure and flat_on_table(s, best[0]) and straight(s, best)):
                g = False
            bases.append(best[0])
        if len(bases) == 2 and not r.is_next_to(*bases):
            g = False
        return ok, len(s.blocks), g

    def _plan(self, b, v):
        W = [x for x in b.s.blocks if color(x) in WARM_COLORS]
        C = [x for x in b.s.blocks if color(x) in COOL_COLORS]
        if v % 2:
            W, C = C, W
        side = ["right", "behind", "left", "front"]
        for c in sorted(((float(x), float(y)) for x in np.arange(-0.2, 0.201, 0.02) for y in np.arange(-0.7, -0.299, 0.02)),
                        key=lambda p: np.hypot(p[0], p[1] + 0.5)):
            for sd in side:
                off = {"right": (NB, 0), "behind": (0, NB), "left": (-NB, 0), "front": (0, -NB)}[sd]
                pts = [c, (c[0] + off[0], c[1] + off[1])]
                if points_free(b.s, pts, [W[0], C[0]], margin=0.01):
                    place_at_points(b, [W[0], C[0]], pts)
                    build_tower(b, W)
                    build_tower(b, C)
                    return
        raise PlanFail("no room")


class R254(Base):
    name = "check-r254"
    description = "Every block with a bowl of its colour is in that bowl; the blocks without one stand lined up on the table in the right third."

    def feasible(self, scene):
        return bool(scene.blocks)

    def _eval(self, s):
        r = relations(s)
        ok, rest = 0, []
        for b in s.blocks:
            w = match_bowl(s, b)
            if w:
                ok += r.in_bowl(b) == w
            else:
                ok += flat_on_table(s, b) and in_col(xy(s, b), "right")
                rest.append(xy(s, b))
        return ok, len(s.blocks), is_line(rest)

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            w = match_bowl(b.s, blk)
            if w and relations(b.s).in_bowl(blk) != w:
                clear_above(b, blk)
                b.do(PutIn(block=blk, bowl=w))
        rest = [x for x in b.s.blocks if not match_bowl(b.s, x)]
        region = lambda p: in_col(p, "right", -0.025)
        if len(rest) == 1:
            move_to_region(b, rest[0], region, (0.2, xy(b.s, rest[0])[1]), allow_bowl=False, allow_stack=False)
        elif rest:
            place_line(b, rest, region, orient=("col", "row"), prefer=(0.2, -0.5 + 0.1 * (v - 1)))


class R259(Base):
    name = "check-r259"
    description = "The yellow block is in the middle of the table, away from the edges."

    def feasible(self, scene):
        return "yellow block" in scene.objects

    def _eval(self, s):
        if "yellow block" not in s.positions:
            return 0, 1, False
        return int(in_cell(xy(s, "yellow block"), "middle")), 1, True

    def _plan(self, b, v):
        move_to_region(b, "yellow block", lambda p: in_cell(p, "middle", -0.025), (0.0, -0.5))


class R265(Base):
    name = "check-r265"
    description = "The blocks are stacked in two-block towers, each tower standing just in front of a bowl (an odd block out may stand anywhere, not on a pair)."

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and len(scene.bowls) >= 1

    def _eval(self, s):
        n = len(s.blocks)
        ok, g = 0, True
        pairs = 0
        for t in towers(s):
            if len(t) > 2:
                g = False
            elif len(t) == 2:
                good = flat_on_table(s, t[0]) and straight(s, t) and any(rel_to_bowl(s, t[0], w, "front") for w in s.bowls)
                ok += 2 * good
                pairs += 1
        if n % 2 == 1:
            ok += 1  # the odd block out (if all pairs are fine, it is fine as long as towers <= 2)
        if pairs != n // 2:
            g = False
        return min(ok, n), n, g

    def _plan(self, b, v):
        blocks = sorted(b.s.blocks)
        np_ = len(blocks) // 2
        bowls = b.s.bowls
        assign = [bowls[(i + v) % len(bowls)] for i in range(np_)]
        pts, bases = [], []
        slot = {w: 0 for w in bowls}
        offs = [0.0, NB, -NB]
        for i in range(np_):
            w = assign[i]
            wx, wy = xy(b.s, w)
            pts.append((wx + offs[slot[w]], wy - NEXT_GAP))
            slot[w] += 1
            bases.append(blocks[2 * i])
        if not points_free(b.s, pts, blocks):
            raise PlanFail("front blocked")
        place_at_points(b, bases, pts)
        for i in range(np_):
            clear_above(b, blocks[2 * i + 1])
            b.do(PutOn(block=blocks[2 * i + 1], target=blocks[2 * i]))
        if len(blocks) % 2:
            odd = blocks[-1]
            if relations(b.s).below(odd):
                move_to_region(b, odd, lambda p: True, xy(b.s, odd), allow_stack=False)


class R267(Base):
    name = "check-r267"
    description = "Cool-coloured blocks are in the back right corner of the table and warm-coloured blocks in the front left corner."

    def feasible(self, scene):
        return bool(scene.blocks)

    def _where(self, blk):
        return "top right corner" if color(blk) in COOL_COLORS else "bottom left corner"

    def _eval(self, s):
        return sum(in_cell(xy(s, x), self._where(x)) for x in s.blocks), len(s.blocks), True

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            c = self._where(blk)
            if in_cell(xy(b.s, blk), c, -0.005):
                continue
            near = (0.27, -0.23) if c == "top right corner" else (-0.27, -0.77)
            move_to_region(b, blk, lambda p, c=c: in_cell(p, c, -0.025), near)


class R274(Base):
    name = "check-r274"
    description = "The blocks are split into two equal groups, one on the left half of the table and one on the right half."
    # An odd number of blocks cannot be split evenly, so such scenes are infeasible.

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and len(scene.blocks) % 2 == 0

    def _eval(self, s):
        L = [b for b in s.blocks if xy(s, b)[0] < -0.01]
        R = [b for b in s.blocks if xy(s, b)[0] > 0.01]
        n = len(s.blocks)
        ok = min(len(L), n // 2) + min(len(R), n - n // 2)
        return ok, n, len(L) == len(R) and len(L) + len(R) == n

    def _plan(self, b, v):
        n = len(b.s.blocks)
        blocks = sorted(b.s.blocks, key=lambda x: xy(b.s, x)[0])
        left, right = blocks[: n // 2], blocks[n // 2:]
        for blk in sorted(b.s.blocks, key=lambda x: -b.s.pos(x)[2]):
            sx = -1 if blk in left else 1
            if sx * xy(b.s, blk)[0] > 0.03:
                continue
            move_to_region(b, blk, lambda p, sx=sx: sx * p[0] > 0.04, (sx * 0.15, xy(b.s, blk)[1]))


class R276(Base):
    name = "check-r276"
    description = "Each block with a bowl of its colour is in that bowl; the others stand in one straight row across the back third of the table."

    def feasible(self, scene):
        return bool(scene.blocks)

    def _eval(self, s):
        r = relations(s)
        ok, rest = 0, []
        for b in s.blocks:
            w = match_bowl(s, b)
            if w:
                ok += r.in_bowl(b) == w
            else:
                ok += flat_on_table(s, b) and in_row(xy(s, b), "top")
                rest.append(xy(s, b))
        g = len(rest) <= 1 or float(np.ptp(np.array(rest)[:, 1])) <= 0.025
        return ok, len(s.blocks), g

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            w = match_bowl(b.s, blk)
            if w and relations(b.s).in_bowl(blk) != w:
                clear_above(b, blk)
                b.do(PutIn(block=blk, bowl=w))
        rest = [x for x in b.s.blocks if not match_bowl(b.s, x)]
        region = lambda p: in_row(p, "top", -0.025)
        if len(rest) == 1:
            move_to_region(b, rest[0], region, (xy(b.s, rest[0])[0], -0.25), allow_bowl=False, allow_stack=False)
        elif rest:
            place_line(b, rest, region, orient=("row",), prefer=(0.1 * (v - 1), -0.25))


class R286(Base):
    name = "check-r286"
    description = "No tower of blocks is more than two blocks high."

    def feasible(self, scene):
        return len(scene.blocks) >= 3  # with fewer blocks a tower of three cannot even be built

    def _eval(self, s):
        return sum(level(s, x) <= 2 for x in s.blocks), len(s.blocks), True

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            if level(b.s, blk) > 2:
                clear_above(b, blk)
                move_to_region(b, blk, lambda p: True, xy(b.s, blk), allow_bowl=False, allow_stack=False)


class R287(Base):
    name = "check-r287"
    description = "The green block is in the bowl furthest to the left."

    def feasible(self, scene):
        return "green block" in scene.objects and len(scene.bowls) >= 1

    def showable(self, scene):
        return self.feasible(scene) and len(scene.bowls) >= 2

    @staticmethod
    def _target(s):
        return min(s.bowls, key=lambda w: s.pos(w)[0], default=None)

    def _eval(self, s):
        t = self._target(s)
        if t is None or "green block" not in s.positions:
            return 0, 1, False
        return int(relations(s).in_bowl("green block") == t), 1, True

    def _plan(self, b, v):
        clear_above(b, "green block")
        b.do(PutIn(block="green block", bowl=self._target(b.s)))


class R300(Base):
    name = "check-r300"
    description = "All blocks are gathered close together in one compact group in the middle of the table."
    # "quiet" is not visible on a final table and is dropped.
    # "close to one another" = the blocks form one connected group with neighbours <= 9.5 cm apart
    # (centre to centre), all inside the middle cell of the table (1 cm tolerance).

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def _eval(self, s):
        mid = [x for x in s.blocks if in_cell(xy(s, x), "middle")]
        # score = the largest close group inside the middle
        best = 0
        for a in mid:
            grp = [a]
            changed = True
            while changed:
                changed = False
                for x in mid:
                    if x not in grp and any(np.hypot(*(xy(s, x) - xy(s, g))) <= 0.095 for g in grp):
                        grp.append(x)
                        changed = True
            best = max(best, len(grp))
        return best, len(s.blocks), True

    def _plan(self, b, v):
        movers = sorted(b.s.blocks)
        offs = [(NB, 0), (-NB, 0), (0, NB), (0, -NB), (NB, NB), (-NB, -NB), (NB, -NB), (-NB, NB)]
        cands = [(float(x), float(y)) for x in np.arange(-0.07, 0.071, 0.01) for y in np.arange(-0.57, -0.429, 0.01)]
        cands.sort(key=lambda p: np.hypot(p[0], p[1] + 0.5))
        for c in cands:
            pts = [c]
            for dx, dy in offs:
                if len(pts) == len(movers):
                    break
                p = (c[0] + dx, c[1] + dy)
                if in_cell(p, "middle", -0.02) and points_free(b.s, pts + [p], movers):
                    pts.append(p)
            if len(pts) == len(movers) and points_free(b.s, pts, movers):
                place_at_points(b, movers, pts)
                return
        # fall back to a single tower in the middle
        spot = find_spot(b.s, lambda p: in_cell(p, "middle", -0.025), (0.0, -0.5), ignore=(movers[0],))
        if spot is None:
            raise PlanFail("middle full")
        clear_above(b, movers[0])
        b.do(PutAt(block=movers[0], position=spot))
        build_tower(b, movers)


class R303(Base):
    name = "check-r303"
    description = "The purple block is in the top left (back left) corner of the table."

    def feasible(self, scene):
        return "purple block" in scene.objects

    def _eval(self, s):
        if "purple block" not in s.positions:
            return 0, 1, False
        return int(in_cell(xy(s, "purple block"), "top left corner")), 1, True

    def _plan(self, b, v):
        move_to_region(b, "purple block", lambda p: in_cell(p, "top left corner", -0.025), (-0.25, -0.25))


class R309(Base):
    name = "check-r309"
    description = "All blocks stand on the table in one straight left-to-right row, each next to the previous with small gaps."
    # "tightly spaced" = neighbouring centres at most 7 cm apart (gap <= 3 cm).

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    @staticmethod
    def _longest_row(s):
        flat = [x for x in s.blocks if flat_on_table(s, x) and clear_top(s, x)]
        best = 0
        for a in flat:
            ya = xy(s, a)[1]
            row = sorted((x for x in flat if abs(xy(s, x)[1] - ya) <= 0.02), key=lambda x: xy(s, x)[0])
            run = 1 if row else 0
            best = max(best, run)
            for p, c in zip(row, row[1:]):
                dx = xy(s, c)[0] - xy(s, p)[0]
                run = run + 1 if 0.035 <= dx <= 0.07 else 1
                best = max(best, run)
        return best

    def _eval(self, s):
        # score = the longest tight row, so pulling a block out of the row counts as moving away
        return self._longest_row(s), len(s.blocks), True

    def _plan(self, b, v):
        place_line(b, list(b.s.blocks), lambda p: True, spacing=0.054, orient=("row",),
                   prefer=(0.0, -0.5 + 0.15 * (v - 1)))


class R320(Base):
    name = "check-r320"
    description = "No block stands loose on the table: every block is in a bowl or part of a stack."

    def feasible(self, scene):
        return bool(scene.blocks) and (bool(scene.bowls) or len(scene.blocks) >= 2)

    def _ok(self, s, x):
        r = relations(s)
        return r.in_bowl(x) is not None or r.below(x) is not None or r.above(x) is not None

    def _eval(self, s):
        return sum(self._ok(s, x) for x in s.blocks), len(s.blocks), True

    def _plan(self, b, v):
        loose = [x for x in b.s.blocks if not self._ok(b.s, x)]
        if b.s.bowls and v == 0:
            for i, x in enumerate(loose):
                b.do(PutIn(block=x, bowl=b.s.bowls[i % len(b.s.bowls)]))
            return
        # stack loose blocks on each other / on an existing stack
        for x in loose:
            if self._ok(b.s, x):
                continue
            others = [t[-1] for t in towers(b.s) if x not in t]
            if not others:
                raise PlanFail("alone")
            b.do(PutOn(block=x, target=others[0]))


class R321(Base):
    name = "check-r321"
    description = "Every block that has a bowl of its colour stands on the table right next to that bowl, on its right side."

    def feasible(self, scene):
        return any(scene_match_bowl(scene, b) for b in scene.blocks)

    def _eval(self, s):
        ok = 0
        for x in s.blocks:
            w = match_bowl(s, x)
            ok += w is None or rel_to_bowl(s, x, w, "right")
        return ok, len(s.blocks), True

    def _plan(self, b, v):
        movers = [x for x in b.s.blocks if match_bowl(b.s, x) and not rel_to_bowl(b.s, x, match_bowl(b.s, x), "right")]
        dy = [0.0, 0.03, -0.03][v % 3]
        pts = [(float(xy(b.s, match_bowl(b.s, x))[0] + NEXT_GAP), float(xy(b.s, match_bowl(b.s, x))[1] + dy)) for x in movers]
        if not points_free(b.s, pts, movers):
            raise PlanFail("right side blocked")
        place_at_points(b, movers, pts)


class R324(Base):
    name = "check-r324"
    description = "Blocks with a bowl of their colour go in that bowl; all other blocks form one tower in the middle of the table."

    def feasible(self, scene):
        return bool(scene.blocks)

    def _eval(self, s):
        r = relations(s)
        ok, rest = 0, []
        for x in s.blocks:
            w = match_bowl(s, x)
            if w:
                ok += r.in_bowl(x) == w
            else:
                rest.append(x)
        g = True
        if rest:
            t = max(towers(s), key=lambda t: sum(x in rest for x in t))
            good = set(t) == set(rest) and flat_on_table(s, t[0]) and in_cell(xy(s, t[0]), "middle") and straight(s, t)
            ok += len(rest) if good else sum(x in rest for x in t) if all(x in rest for x in t) and len(t) > 1 else 0
            g = good
        return ok, len(s.blocks), g

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            w = match_bowl(b.s, blk)
            if w and relations(b.s).in_bowl(blk) != w:
                clear_above(b, blk)
                b.do(PutIn(block=blk, bowl=w))
        rest = [x for x in b.s.blocks if not match_bowl(b.s, x)]
        if not rest:
            return
        rest = rest[v % len(rest):] + rest[: v % len(rest)]
        move_to_region(b, rest[0], lambda p: in_cell(p, "middle", -0.025), (0.0, -0.5), allow_bowl=False, allow_stack=False)
        build_tower(b, rest)


class R325(Base):
    name = "check-r325"
    description = "All the blocks are stacked into a single straight tower."

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def _eval(self, s):
        t = max(towers(s), key=len)
        return len(t), len(s.blocks), straight(s, t)

    def _plan(self, b, v):
        t = max(towers(b.s), key=len)
        if not straight(b.s, t) or relations(b.s).in_bowl(t[0]):
            t = [t[0]]
        rest = [x for x in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]) if x not in t]
        if v == 1:
            flatten(b)
            t = [sorted(b.s.blocks)[0]]
            rest = [x for x in b.s.blocks if x not in t]
        build_tower(b, [t[-1]] + rest)


class R331(Base):
    name = "check-r331"
    description = "No block is on the right half of the table."
    # "right side" read as the right half (block centres at x <= 0); blocks in bowls count too.

    def feasible(self, scene):
        return bool(scene.blocks)

    def _eval(self, s):
        return sum(xy(s, x)[0] <= 0.005 for x in s.blocks), len(s.blocks), True

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            if xy(b.s, blk)[0] <= 0.0:
                continue
            move_to_region(b, blk, lambda p: p[0] <= -0.03, (-0.1, xy(b.s, blk)[1]))


class R337(Base):
    name = "check-r337"
    description = "One block in each corner of the table (as many corners as there are blocks, up to four), and any remaining blocks in the middle."
    # With fewer than four blocks each block takes a different corner and the middle stays empty.

    def feasible(self, scene):
        return bool(scene.blocks)

    def _eval(self, s):
        used, ok, mid = set(), 0, 0
        for x in s.blocks:
            c = next((c for c in CORNERS if in_cell(xy(s, x), c)), None)
            if c is not None and c not in used:
                used.add(c)
                ok += 1
            elif in_cell(xy(s, x), "middle"):
                mid += 1
        n = len(s.blocks)
        want_corners = min(n, 4)
        ok_total = min(len(used), want_corners) + min(mid, n - want_corners)
        return ok_total, n, len(used) == want_corners and mid == n - want_corners

    def _plan(self, b, v):
        blocks = sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2])
        near = {"top left corner": (-0.27, -0.23), "top right corner": (0.27, -0.23),
                "bottom left corner": (-0.27, -0.77), "bottom right corner": (0.27, -0.77)}
        used = set()
        todo = []
        for x in blocks:
            c = next((c for c in CORNERS if in_cell(xy(b.s, x), c, -0.005)), None)
            if c and c not in used and len(used) < 4 and flat_on_table(b.s, x):
                used.add(c)
            else:
                todo.append(x)
        free_c = [c for c in CORNERS if c not in used]
        free_c = free_c[v % max(1, len(free_c)):] + free_c[: v % max(1, len(free_c))]
        for x in todo:
            if free_c:
                c = free_c.pop(0)
                move_to_region(b, x, lambda p, c=c: in_cell(p, c, -0.025), near[c], allow_stack=False)
            else:
                move_to_region(b, x, lambda p: in_cell(p, "middle", -0.025), (0.0, -0.5))


class R341(Base):
    name = "check-r341"
    description = "Every block stands flat on the table, nothing stacked or in bowls, spread apart from the other blocks, right next to the bowl of its own colour."
    # "spread out" = no two blocks closer than 7 cm centre to centre.

    def feasible(self, scene):
        return bool(scene.blocks) and all(scene_match_bowl(scene, x) for x in scene.blocks)

    def _eval(self, s):
        r = relations(s)
        ok = 0
        for x in s.blocks:
            w = match_bowl(s, x)
            ok += flat_on_table(s, x) and clear_top(s, x) and w is not None and r.is_next_to(x, w)
        g = all(np.hypot(*(xy(s, a) - xy(s, c))) >= 0.07 for a, c in itertools.combinations(s.blocks, 2))
        return ok, len(s.blocks), g

    def _plan(self, b, v):
        movers = list(b.s.blocks)
        sides = {"right": (1, 0), "left": (-1, 0), "behind": (0, 1), "front": (0, -1)}
        opts = []
        for x in movers:
            wx, wy = xy(b.s, match_bowl(b.s, x))
            o = []
            for sd, (ux, uy) in sides.items():
                p = (wx + ux * NEXT_GAP, wy + uy * NEXT_GAP)
                if is_free(b.s, p[0], p[1], ignore=movers, margin=0.004, edge=0.005):
                    o.append(p)
            o.sort(key=lambda p: np.hypot(*(np.array(p) - xy(b.s, x))))
            opts.append(o)
        for combo in itertools.product(*opts):
            if all(np.hypot(p[0] - q[0], p[1] - q[1]) >= 0.08 for p, q in itertools.combinations(combo, 2)):
                place_at_points(b, movers, list(combo))
                return
        raise PlanFail("no spread placement")


class R344(Base):
    name = "check-r344"
    description = "Every block is in the front third of the table, near the person."

    def feasible(self, scene):
        return bool(scene.blocks)

    def _eval(self, s):
        return sum(in_row(xy(s, x), "bottom") for x in s.blocks), len(s.blocks), True

    def _plan(self, b, v):
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            if in_row(xy(b.s, blk), "bottom", -0.005):
                continue
            move_to_region(b, blk, lambda p: in_row(p, "bottom", -0.025), (xy(b.s, blk)[0], -0.72))


class R348(Base):
    name = "check-r348"
    description = "All non-red blocks are together in one bowl, and the red block is in a different bowl that holds only red."

    def feasible(self, scene):
        nonred = [x for x in scene.blocks if x != "red block"]
        if not scene.blocks or not scene.bowls:
            return False
        if "red block" in scene.objects and nonred:
            return len(scene.bowls) >= 2
        return True

    def _eval(self, s):
        r = relations(s)
        nonred = [x for x in s.blocks if x != "red block"]
        ok = 0
        bowls_nr = {r.in_bowl(x) for x in nonred}
        g = True
        if nonred:
            from collections import Counter
            cnt = Counter(r.in_bowl(x) for x in nonred if r.in_bowl(x))
            main = cnt.most_common(1)[0][0] if cnt else None
            ok += sum(r.in_bowl(x) == main and main is not None for x in nonred)
            g = len(bowls_nr) == 1 and main is not None
        else:
            main = None
        if "red block" in s.positions:
            rw = r.in_bowl("red block")
            ok += rw is not None and rw != main
        return ok, len(s.blocks), g

    def _plan(self, b, v):
        bowls = b.s.bowls
        nonred = [x for x in b.s.blocks if x != "red block"]
        main = bowls[v % len(bowls)]
        redb = next((w for w in bowls if w != main), None)
        if "red block" in b.s.positions and "red bowl" in bowls and "red bowl" != main:
            redb = "red bowl"
        # get red out of main first, then fill
        for blk in sorted(b.s.blocks, key=lambda n: -b.s.pos(n)[2]):
            want = redb if blk == "red block" else main
            if relations(b.s).in_bowl(blk) != want:
                clear_above(b, blk)
                b.do(PutIn(block=blk, bowl=want))
        del nonred


class R359(Base):
    name = "check-r359"
    description = "Each block stands just in front of a different bowl, one block per bowl."
    # Needs at least as many bowls as blocks; with more bowls some stay without a block.

    def feasible(self, scene):
        return 1 <= len(scene.blocks) <= len(scene.bowls)

    def _eval(self, s):
        used, ok = set(), 0
        # greedy matching is enough: a block is just in front of at most one bowl
        for x in s.blocks:
            w = next((w for w in s.bowls if w not in used and rel_to_bowl(s, x, w, "front")), None)
            if w:
                used.add(w)
                ok += 1
        return ok, len(s.blocks), True

    def _plan(self, b, v):
        blocks = sorted(b.s.blocks, key=lambda x: xy(b.s, x)[0])
        bowls = sorted(b.s.bowls, key=lambda w: xy(b.s, w)[0])
        dx = [0.0, 0.03, -0.03][v % 3]
        for perm in itertools.permutations(bowls, len(blocks)):
            pts = [(float(xy(b.s, w)[0] + dx), float(xy(b.s, w)[1] - NEXT_GAP)) for w in perm]
            if points_free(b.s, pts, blocks):
                place_at_points(b, blocks, pts)
                return
        raise PlanFail("front blocked")


ALL = [R193, R214, R225, R228, R231, R236, R244, R246, R249, R254, R259, R265, R267, R274, R276,
       R286, R287, R300, R303, R309, R320, R321, R324, R325, R331, R337, R341, R344, R348, R359]
