"""Checkers for requests r001 ... r189 (set A): one Intention class per request.

Conventions (from src/activeintent/world): x grows left -> right, y grows front -> back
(front = y near -0.8, "bottom" in the Code-as-Policies names; back = y near -0.2, "top").
The table is split into a 3 x 3 grid of 20 cm cells (columns at x = -0.1 / 0.1, rows at
y = -0.6 / -0.4). Checks allow about a centimetre of settling noise.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    COLOR_NAMES,
    COLORS,
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

# ----------------------------------------------------------------------------------------
# shared geometry
# ----------------------------------------------------------------------------------------

TOL = 0.012  # settling tolerance (m)
CENTRE = (0.0, -0.5)
BOWL_R = 0.065
SIDE_OFFSET = BOWL_R + BLOCK_SIZE / 2 + 0.012  # PutNextTo distance from a bowl's centre
SIDE_VEC = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "front": (0.0, -1.0), "behind": (0.0, 1.0)}
TABLE = (-0.28, 0.28, -0.78, -0.22)  # where planned block centres may go (x0, x1, y0, y1)

# grid cells (x0, x1, y0, y1)
LEFT_COL = (-0.3, -0.1, -0.8, -0.2)
MID_COL = (-0.1, 0.1, -0.8, -0.2)
RIGHT_COL = (0.1, 0.3, -0.8, -0.2)
MIDDLE_CELL = (-0.1, 0.1, -0.6, -0.4)
FRONT_RIGHT_CELL = (0.1, 0.3, -0.8, -0.6)
BACK_ROW = (-0.3, 0.3, -0.4, -0.2)


def _lin(c: float) -> float:
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def luminance(color: str) -> float:
    """Relative luminance (sRGB, linearised) of a palette colour: larger = lighter."""
    r, g, b = COLORS[color]
    return 0.2126 * _lin(r) + 0.7152 * _lin(g) + 0.0722 * _lin(b)


# dark -> light: purple, blue, brown, red, green, orange, cyan, gray, pink, yellow
LIGHTNESS_ORDER = tuple(sorted(COLOR_NAMES, key=luminance))


def color(name: str) -> str:
    return name.split(" ", 1)[0]


def kind(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


def xy(state: WorldState, name: str) -> tuple[float, float]:
    p = state.positions[name]
    return float(p[0]), float(p[1])


def in_box(p, box, tol: float = TOL) -> bool:
    x0, x1, y0, y1 = box
    return x0 - tol <= p[0] <= x1 + tol and y0 - tol <= p[1] <= y1 + tol


def shrink(box, m: float):
    x0, x1, y0, y1 = box
    return (max(x0 + m, TABLE[0]), min(x1 - m, TABLE[1]), max(y0 + m, TABLE[2]), min(y1 - m, TABLE[3]))


def dist(a, b) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def chains(state: WorldState, rel=None) -> list[list[str]]:
    """Stacks as lists of blocks, bottom first (a lone block is a stack of one)."""
    rel = rel or relations(state)
    out = []
    for b in state.blocks:
        if rel.below(b) is not None:
            continue
        c, seen = [b], {b}
        while (t := rel.above(c[-1])) is not None and t not in seen:
            c.append(t)
            seen.add(t)
        out.append(c)
    return out


def chain_of(state: WorldState, block: str, rel=None) -> list[str]:
    for c in chains(state, rel):
        if block in c:
            return c
    return [block]


def bowl_of_color(state_or_scene, c: str) -> str | None:
    name = f"{c} bowl"
    objs = state_or_scene.positions if isinstance(state_or_scene, WorldState) else state_or_scene.objects
    return name if name in objs else None


def centre_bowl(state: WorldState) -> str | None:
    """The bowl covering the table centre (no block can stand there), if any."""
    near = [w for w in state.bowls if dist(xy(state, w), CENTRE) < BOWL_R + BLOCK_SIZE / 2 + 0.004]
    return min(near, key=lambda w: dist(xy(state, w), CENTRE)) if near else None


def bowl_contents(state: WorldState, rel=None) -> dict[str, list[str]]:
    rel = rel or relations(state)
    out = {w: [] for w in state.bowls}
    for b in state.blocks:
        w = rel.in_bowl(b)
        if w is not None:
            out[w].append(b)
    return out


# ----------------------------------------------------------------------------------------
# plan builder: applies skills with the symbolic model as it goes
# ----------------------------------------------------------------------------------------


class PlanFail(Exception):
    pass


class Builder:
    def __init__(self, state: WorldState, reserved=(), park_box=TABLE, park_pred=None):
        self.s = state
        self.steps: list[Skill] = []
        self.reserved = [tuple(r) for r in reserved]
        self.done: set[str] = set()
        self.park_box = park_box
        self.park_pred = park_pred

    @property
    def rel(self):
        return relations(self.s)

    def do(self, step) -> None:
        new, fail = apply_skill(self.s, step)
        if fail is not None:
            raise PlanFail(fail.reason)
        self.s = new
        self.steps.append(step)
        if len(self.steps) > 40:
            raise PlanFail("plan too long")

    # -- free places ------------------------------------------------------------------
    def free(self, p, moving=None, clearance=0.006, use_reserved=True) -> bool:
        x, y = p
        if not (TABLE[0] - 1e-9 <= x <= TABLE[1] + 1e-9 and TABLE[2] - 1e-9 <= y <= TABLE[3] + 1e-9):
            return False
        for o, q in self.s.positions.items():
            if o == moving:
                continue
            if kind(o) == "block" and q[2] > BLOCK_SIZE:
                continue  # stacked: its base is checked
            r = BOWL_R if kind(o) == "bowl" else BLOCK_SIZE / 2
            if math.hypot(q[0] - x, q[1] - y) < r + BLOCK_SIZE / 2 + 0.004 + clearance:
                return False
        if use_reserved:
            for r in self.reserved:
                if math.hypot(r[0] - x, r[1] - y) < 0.055:
                    return False
        return True

    def find(self, moving, box=TABLE, prefer=None, pred=None, step=None):
        box = shrink(box, 0.0)
        x0, x1, y0, y1 = box
        if x0 > x1 or y0 > y1:
            return None
        if prefer is None:
            prefer = xy(self.s, moving) if moving else CENTRE
        step = step or (0.01 if (x1 - x0) * (y1 - y0) < 0.08 else 0.015)
        xs = np.arange(x0, x1 + 1e-9, step)
        ys = np.arange(y0, y1 + 1e-9, step)
        gx, gy = np.meshgrid(xs, ys)
        pts = np.stack([gx.ravel(), gy.ravel()], 1)
        order = np.argsort(np.hypot(pts[:, 0] - prefer[0], pts[:, 1] - prefer[1]), kind="stable")
        for i in order:
            p = (round(float(pts[i, 0]), 3), round(float(pts[i, 1]), 3))
            if pred is not None and not pred(p):
                continue
            if self.free(p, moving):
                return p
        return None

    # -- moves ------------------------------------------------------------------------
    def clear(self, block: str) -> None:
        top = self.rel.above(block)
        if top is not None:
            self.clear(top)
            self.park(top)

    def park(self, block: str, box=None, prefer=None, pred=None) -> None:
        """Move a block (and what is on it) to a free place on the table."""
        self.clear(block)
        preds = [f for f in (pred, self.park_pred) if f is not None]
        full = (lambda p: all(f(p) for f in preds)) if preds else None
        p = self.find(block, box or self.park_box, prefer, full)
        if p is None and box is None and self.park_box is not TABLE:
            p = self.find(block, TABLE, prefer, full)
        if p is None:
            raise PlanFail(f"no room to park {block}")
        self.do(PutAt(block=block, position=p))

    def make_room(self, p, moving=None, radius=0.05) -> None:
        """Park the blocks standing where a block should go at p; fail if a bowl is there."""
        for o, q in list(self.s.positions.items()):
            if o == moving:
                continue
            if kind(o) == "bowl":
                if math.hypot(q[0] - p[0], q[1] - p[1]) < BOWL_R + BLOCK_SIZE / 2 + 0.004:
                    raise PlanFail(f"the {o} is in the way")
                continue
            q = self.s.positions[o]
            if q[2] > BLOCK_SIZE or self.rel.in_bowl(o):
                continue
            if math.hypot(q[0] - p[0], q[1] - p[1]) < radius:
                if o in self.done:
                    raise PlanFail(f"{o} is already placed")
                self.park(o, pred=lambda c: math.hypot(c[0] - p[0], c[1] - p[1]) > 0.06)

    def put_at(self, block: str, p) -> None:
        self.clear(block)
        self.make_room(p, block)
        self.do(PutAt(block=block, position=(round(float(p[0]), 3), round(float(p[1]), 3))))

    def put_in(self, block: str, bowl: str) -> None:
        self.clear(block)
        self.do(PutIn(block=block, bowl=bowl))

    def put_on(self, block: str, target: str) -> None:
        self.clear(block)
        top = self.rel.above(target)
        if top is not None and top != block:
            self.clear(target)
        self.do(PutOn(block=block, target=target))

    def top_of(self, block: str) -> str:
        c = chain_of(self.s, block, self.rel)
        return c[-1]

    def put_next_to(self, block: str, target: str, side: str = "nearest") -> None:
        self.clear(block)
        t = xy(self.s, target)
        off = (BOWL_R if kind(target) == "bowl" else BLOCK_SIZE / 2) + BLOCK_SIZE / 2 + 0.012
        if side == "nearest":
            here = xy(self.s, block)
            sides = sorted(SIDE_VEC, key=lambda s: dist((t[0] + off * SIDE_VEC[s][0], t[1] + off * SIDE_VEC[s][1]), here))
        else:
            sides = [side]
        # first a side that is free already, then one that can be freed
        for s in sides:
            p = (t[0] + off * SIDE_VEC[s][0], t[1] + off * SIDE_VEC[s][1])
            if apply_skill(self.s, PutNextTo(block=block, target=target, side=s))[1] is None:
                self.do(PutNextTo(block=block, target=target, side=s))
                return
        for s in sides:
            p = (t[0] + off * SIDE_VEC[s][0], t[1] + off * SIDE_VEC[s][1])
            if not (TABLE[0] - 0.04 <= p[0] <= TABLE[1] + 0.04 and TABLE[2] - 0.04 <= p[1] <= TABLE[3] + 0.04):
                continue
            saved = (self.s, list(self.steps))
            try:
                self.make_room(p, block)
                self.do(PutNextTo(block=block, target=target, side=s))
                return
            except PlanFail:
                self.s, self.steps = saved
        raise PlanFail(f"no free side of {target}")

    def place_in_box(self, block: str, box, prefer=None, allow_stack=True, stack_ok=None, margin=0.02) -> None:
        """Put a block on the table inside box (or on a stack standing in box)."""
        self.clear(block)
        p = self.find(block, shrink(box, margin), prefer)
        if p is not None:
            self.do(PutAt(block=block, position=p))
            return
        if allow_stack:
            rel = self.rel
            own = chain_of(self.s, block, rel)
            tops = []
            for c in chains(self.s, rel):
                if block in c or c[0] in own:
                    continue
                base = c[0]
                if rel.in_bowl(base) is None and in_box(xy(self.s, base), box, 0.0):
                    if stack_ok is None or stack_ok(c):
                        tops.append(c[-1])
            if tops:
                pr = prefer or xy(self.s, block)
                tgt = min(tops, key=lambda b: (len(chain_of(self.s, b, rel)), dist(xy(self.s, b), pr)))
                self.do(PutOn(block=block, target=tgt))
                return
        raise PlanFail(f"no room for {block} in {box}")


# ----------------------------------------------------------------------------------------
# common base class
# ----------------------------------------------------------------------------------------


class _Check(Intention):
    """Per-block rule: satisfied when every relevant block is ok and the global condition holds."""

    must: tuple[str, ...] = ()  # objects the rule needs (used by sample_scene)
    min_blocks = 1
    min_bowls = 0
    independent = True  # a moved relevant block left misplaced is a move away

    # -- to override --------------------------------------------------------------------
    def relevant(self, state: WorldState) -> list[str]:
        return list(state.blocks)

    def block_ok(self, state: WorldState, rel, b: str) -> bool:
        return True

    def global_ok(self, state: WorldState, rel) -> bool:
        return True

    def build(self, b: Builder) -> None:
        raise PlanFail("no planner")

    def builders(self, state: WorldState):
        return [Builder(state)]

    # -- Intention API ------------------------------------------------------------------
    def satisfied(self, state: WorldState) -> bool:
        rel = relations(state)
        return all(self.block_ok(state, rel, b) for b in self.relevant(state)) and self.global_ok(state, rel)

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        rel = relations(state)
        bl = self.relevant(state)
        if not bl:
            return 0.0
        s = sum(self.block_ok(state, rel, b) for b in bl) / len(bl)
        return min(s, 1.0 - 0.5 / len(bl))

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if self.score(after) < self.score(before) - 1e-9:
            return True
        if self.independent and step.block in self.relevant(after):
            return not self.block_ok(after, relations(after), step.block)
        return False

    def feasible(self, scene: Scene) -> bool:
        objs = set(scene.objects)
        return (
            all(m in objs for m in self.must)
            and len(scene.blocks) >= self.min_blocks
            and len(scene.bowls) >= self.min_bowls
        )

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        for _ in range(300):
            sc = sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2), matching=bool(rng.integers(2)) or None)
            if len(sc.objects) <= 5 and self.feasible(sc):
                return sc
        # build one around the needed objects
        for _ in range(300):
            objs = list(self.must)
            n = int(rng.integers(max(3, len(objs)), 6))
            while len(objs) < n:
                k = "block" if rng.random() < 0.6 else "bowl"
                o = f"{rng.choice(COLOR_NAMES)} {k}"
                if o not in objs:
                    objs.append(o)
            sc = Scene(objects=objs)
            if self.feasible(sc):
                return sc
        raise RuntimeError(f"cannot sample a scene for {self.name}")

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.satisfied(state):
            return []
        for b in self.builders(state):
            try:
                for _ in range(3):  # a later move may have disturbed an earlier one: go again
                    self.build(b)
                    if self.satisfied(b.s):
                        return b.steps
            except PlanFail:
                continue
        return None


class _RegionRule(_Check):
    """Each relevant block must stand in a box (block centre, with tolerance)."""

    box = TABLE
    allow_bowl = True  # may the block sit in a bowl inside the box

    def prefer(self, state, b):
        return None

    def block_ok(self, state, rel, b):
        if not self.allow_bowl and rel.in_bowl(b) is not None:
            return False
        return in_box(xy(state, b), self.box)

    def build(self, bd: Builder) -> None:
        for b in sorted(self.relevant(bd.s), key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                bd.done.add(b)
                continue
        for b in sorted(self.relevant(bd.s), key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                bd.done.add(b)
                continue
            bd.place_in_box(b, self.box, self.prefer(bd.s, b))
            bd.done.add(b)

    def builders(self, state):
        return [Builder(state, park_pred=lambda p: in_box(p, self.box, -0.01))]


# ----------------------------------------------------------------------------------------
# the requests
# ----------------------------------------------------------------------------------------


class R001(_Check):
    name = "check-r001"
    description = (
        "Put every block in the bowl of its own colour, and leave any block without a matching "
        "bowl on the table in the middle of the table."
    )

    def block_ok(self, state, rel, b):
        w = bowl_of_color(state, color(b))
        if w is not None:
            return rel.in_bowl(b) == w
        return rel.in_bowl(b) is None and in_box(xy(state, b), MIDDLE_CELL)

    def build(self, bd):
        blocks = sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2])
        for b in blocks:
            w = bowl_of_color(bd.s, color(b))
            if w is not None and bd.rel.in_bowl(b) != w:
                bd.put_in(b, w)
        for b in blocks:
            if bowl_of_color(bd.s, color(b)) is None:
                if not self.block_ok(bd.s, bd.rel, b):
                    bd.place_in_box(b, MIDDLE_CELL, CENTRE)
                bd.done.add(b)


class R012(_RegionRule):
    name = "check-r012"
    description = "Put the green block in the front right corner of the table."
    # front right corner = the front-right cell of the 3 x 3 table grid (x > 0.1, y < -0.6);
    # the other blocks are free.
    must = ("green block",)
    box = FRONT_RIGHT_CELL
    allow_bowl = False  # "in the corner" on the table, not inside a bowl standing there

    def relevant(self, state):
        return [b for b in state.blocks if color(b) == "green"]

    def prefer(self, state, b):
        return (0.25, -0.75)

    def builders(self, state):
        return [Builder(state)]


class _NextToMatchingBowl(_Check):
    """Every block that has a bowl of its colour stands next to it (on `side`), not in it."""

    side = "nearest"

    def relevant(self, state):
        return [b for b in state.blocks if bowl_of_color(state, color(b))]

    def feasible(self, scene):
        return any(f"{color(b)} bowl" in scene.objects for b in scene.blocks)

    def sample_scene(self, rng):
        for _ in range(300):
            sc = sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2), matching=True)
            if len(sc.objects) <= 5 and self.feasible(sc):
                return sc
        return Scene(objects=["red block", "red bowl", "blue block"])

    def direction_ok(self, d) -> bool:
        return True

    def block_ok(self, state, rel, b):
        w = bowl_of_color(state, color(b))
        if rel.in_bowl(b) is not None or not rel.is_next_to(b, w):
            return False
        p, q = xy(state, b), xy(state, w)
        return self.direction_ok((p[0] - q[0], p[1] - q[1]))

    def build(self, bd):
        # the blocks to place; blocks already right are kept
        todo = [b for b in self.relevant(bd.s) if not self.block_ok(bd.s, bd.rel, b)]
        for b in self.relevant(bd.s):
            if b not in todo:
                bd.done.add(b)
        # keep the wanted spots clear while parking
        spots = []
        if self.side != "nearest":
            for b in todo:
                q = xy(bd.s, bowl_of_color(bd.s, color(b)))
                v = SIDE_VEC[self.side]
                spots.append((q[0] + SIDE_OFFSET * v[0], q[1] + SIDE_OFFSET * v[1]))
        bd.reserved = spots
        for b in sorted(todo, key=lambda n: -bd.s.positions[n][2]):
            bd.put_next_to(b, bowl_of_color(bd.s, color(b)), self.side)
            bd.done.add(b)


class R030(_NextToMatchingBowl):
    name = "check-r030"
    description = "Place every block just to the right of the bowl of its own colour, not inside it."
    side = "right"

    def direction_ok(self, d):
        return d[0] > 0.03 and abs(d[1]) <= d[0]


class _Tower(_Check):
    """All blocks in one single stack whose base satisfies base_ok."""

    min_blocks = 2
    independent = False

    def base_ok(self, state, rel, base) -> bool:
        return True

    def good_chain(self, state, rel, c) -> bool:
        return self.base_ok(state, rel, c[0])

    def satisfied(self, state):
        rel = relations(state)
        cs = chains(state, rel)
        return len(cs) == 1 and len(cs[0]) == len(state.blocks) and self.good_chain(state, rel, cs[0])

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        rel = relations(state)
        n = len(state.blocks)
        if n == 0:
            return 0.0
        best = max((len(c) for c in chains(state, rel) if self.good_chain(state, rel, c)), default=0)
        return min(best / n, 1 - 0.5 / n)

    def step_moves_away(self, before, after, step):
        if self.score(after) < self.score(before) - 1e-9:
            return True
        rel = relations(after)
        c = chain_of(after, step.block, rel)
        if not self.good_chain(after, rel, c):
            return True
        # a lone block moved (not onto a stack) is wasted unless it became a good base
        return len(c) == 1 and self.score(after) <= self.score(before) + 1e-9

    def base_spot(self, bd: Builder):
        """Return ('xy', point) / ('bowl', bowl) / ('block', base block) for the base."""
        return None

    def build(self, bd):
        blocks = sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2])
        rel = bd.rel
        # reuse a good existing chain as the base (keep its blocks)
        good = [c for c in chains(bd.s, rel) if self.good_chain(bd.s, rel, c)]
        if good:
            base_chain = max(good, key=len)
        else:
            kind_, where = self.base_spot(bd)
            bd.reserved = [where] if kind_ == "xy" else []
            # base: a block with nothing on it, nearest the spot
            clear_blocks = [b for b in bd.s.blocks if rel.above(b) is None]
            target = where if kind_ == "xy" else xy(bd.s, where) if kind_ == "bowl" else None
            if kind_ == "block":
                base = where
            else:
                base = min(clear_blocks, key=lambda b: dist(xy(bd.s, b), target))
            if kind_ == "xy":
                bd.reserved = []
                bd.put_at(base, where)
            elif kind_ == "bowl":
                bd.put_in(base, where)
            bd.reserved = [xy(bd.s, base)]
            base_chain = [base]
        for b in base_chain:
            bd.done.add(b)
        # cut off anything wrongly left above the base chain
        top = base_chain[-1]
        for b in blocks:
            if b in base_chain:
                continue
            bd.put_on(b, top)
            top = b


class R035(_Tower):
    name = "check-r035"
    description = "Stack all the blocks into a single pile standing in the front right corner of the table."
    # the pile stands on the table (not in a bowl) in the front-right cell of the 3 x 3 grid.

    def base_ok(self, state, rel, base):
        return rel.in_bowl(base) is None and in_box(xy(state, base), FRONT_RIGHT_CELL)

    def base_spot(self, bd):
        p = bd.find(None, shrink(FRONT_RIGHT_CELL, 0.02), (0.25, -0.75))
        if p is None:  # only blocks in the way: ignore them and make room
            for cand in [(0.25, -0.75), (0.2, -0.7), (0.25, -0.65), (0.15, -0.75)]:
                if all(dist(cand, xy(bd.s, w)) > BOWL_R + 0.03 for w in bd.s.bowls):
                    return "xy", cand
            raise PlanFail("corner taken by bowls")
        return "xy", p


class R037(_Tower):
    name = "check-r037"
    description = "Stack every block into one single tower standing at the exact centre of the table."
    # "Structure first, always" is a priority on how the robot works, not on the final table:
    # dropped. "Tallest you can" = every block in the tower. If a bowl covers the centre (no
    # block can stand there), a tower built inside that bowl counts as at the centre.
    CENTRE_TOL = 0.03

    def base_ok(self, state, rel, base):
        if dist(xy(state, base), CENTRE) <= self.CENTRE_TOL:
            return True
        # a bowl covers the centre: the tower is built in that bowl
        w = centre_bowl(state)
        return w is not None and rel.in_bowl(base) == w

    def base_spot(self, bd):
        w = centre_bowl(bd.s)
        if w is not None:
            return "bowl", w
        return "xy", CENTRE


class R039(_Check):
    name = "check-r039"
    description = (
        "Arrange the blocks mirror-symmetrically about the table's left-right centre line, "
        "with the odd block, if any, at the dead centre of the table."
    )
    # Bowls cannot be moved, so the symmetry is judged on the blocks only.
    min_blocks = 2
    independent = False
    PAIR_TOL = 0.03
    CENTRE_TOL = 0.03

    def _mirrors(self, state, a, b):
        pa, pb = state.positions[a], state.positions[b]
        return (
            abs(pa[0] + pb[0]) <= self.PAIR_TOL
            and abs(pa[1] - pb[1]) <= self.PAIR_TOL
            and abs(pa[2] - pb[2]) <= 0.015
            and min(pa[0], pb[0]) < -0.015
        )

    def _matched(self, state, blocks) -> int:
        """Largest number of blocks that can be split into mirror pairs."""
        if len(blocks) < 2:
            return 0
        a, rest = blocks[0], blocks[1:]
        best = self._matched(state, rest)
        for i, b in enumerate(rest):
            if self._mirrors(state, a, b):
                best = max(best, 2 + self._matched(state, rest[:i] + rest[i + 1 :]))
        return best

    def _centre_ok(self, state, c) -> bool:
        p = xy(state, c)
        if dist(p, CENTRE) <= self.CENTRE_TOL:
            return True
        # a bowl covers the dead centre: the odd block may stand on the centre line near it
        return centre_bowl(state) is not None and abs(p[0]) <= 0.02 and abs(p[1] - CENTRE[1]) <= 0.15

    def _best(self, state) -> int:
        blocks = list(state.blocks)
        n = len(blocks)
        if n % 2 == 0:
            return self._matched(state, blocks)
        best = self._matched(state, blocks)
        for c in blocks:
            if self._centre_ok(state, c):
                best = max(best, 1 + self._matched(state, [b for b in blocks if b != c]))
        return best

    def satisfied(self, state):
        n = len(state.blocks)
        if n == 0:
            return True
        if n % 2 == 0:
            return self._matched(state, list(state.blocks)) == n
        blocks = list(state.blocks)
        for c in blocks:
            if self._centre_ok(state, c):
                if self._matched(state, [b for b in blocks if b != c]) == n - 1:
                    return True
        return False

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        return min(self._best(state) / max(n, 1), 1 - 0.5 / max(n, 1))

    def build(self, bd):
        blocks = sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2])
        # first put everything on the table, alone
        for b in blocks:
            if bd.s.positions[b][2] > BLOCK_SIZE or bd.rel.in_bowl(b) is not None:
                bd.park(b)
        blocks = sorted(bd.s.blocks, key=lambda n: bd.s.positions[n][0])
        if len(blocks) % 2 == 1:
            mid = min(blocks, key=lambda b: dist(xy(bd.s, b), CENTRE))
            blocks.remove(mid)
            if centre_bowl(bd.s) is None:
                bd.put_at(mid, CENTRE)
            else:
                p = bd.find(mid, (0.0, 0.0, -0.64, -0.36), CENTRE, step=0.005)
                if p is None:
                    raise PlanFail("no place on the centre line")
                bd.put_at(mid, p)
            bd.done.add(mid)
        # pairs: leftmost with rightmost, and so on
        while blocks:
            a, b = blocks.pop(0), blocks.pop(-1)
            spot = None
            pa = xy(bd.s, a)
            cands = [
                (x, y)
                for x in np.arange(0.05, 0.271, 0.01)
                for y in np.arange(-0.77, -0.229, 0.01)
            ]
            cands.sort(key=lambda p: dist((-p[0], p[1]), pa))
            for x, y in cands:
                l, r = (round(-float(x), 3), round(float(y), 3)), (round(float(x), 3), round(float(y), 3))
                if bd.free(l, a) and bd.free(r, b) and dist(xy(bd.s, b), l) > 0.06 and dist(pa, r) > 0.06:
                    spot = (l, r)
                    break
            if spot is None:
                raise PlanFail("no symmetric places")
            bd.do(PutAt(block=a, position=spot[0]))
            bd.do(PutAt(block=b, position=spot[1]))
            bd.done |= {a, b}


class R040(_Check):
    name = "check-r040"
    description = (
        "Stack the blocks in pairs, two to a stack, with the darker-coloured block underneath "
        "and the lighter one on top (an odd block left on its own)."
    )
    # "Darker" is judged by relative luminance of the palette colours:
    # purple < blue < brown < red < green < orange < cyan < gray < pink < yellow.
    min_blocks = 2
    independent = False

    @staticmethod
    def _valid_pair(c):
        return len(c) == 2 and luminance(color(c[0])) < luminance(color(c[1]))

    def satisfied(self, state):
        cs = chains(state)
        n = len(state.blocks)
        if any(len(c) > 2 for c in cs):
            return False
        pairs = [c for c in cs if len(c) == 2]
        return len(pairs) == n // 2 and all(self._valid_pair(c) for c in pairs)

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        n = len(state.blocks)
        if n < 2:
            return 0.0
        good = sum(1 for c in chains(state) if self._valid_pair(c))
        return min(good / (n // 2), 1 - 0.5 / n)

    def step_moves_away(self, before, after, step):
        if self.score(after) < self.score(before) - 1e-9:
            return True
        c = chain_of(after, step.block)
        return not self._valid_pair(c)

    def build(self, bd):
        rel = bd.rel
        keep = [c for c in chains(bd.s, rel) if self._valid_pair(c)]
        kept = {b for c in keep for b in c}
        # flatten everything else
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if b in kept:
                continue
            r = bd.rel
            if r.below(b) is not None or r.above(b) is not None:
                bd.park(b)
        rest = sorted([b for b in bd.s.blocks if b not in kept], key=lambda b: luminance(color(b)))
        k = len(bd.s.blocks) // 2 - len(keep)
        rest = rest[: 2 * k]
        for i in range(0, len(rest) - 1, 2):
            dark, light = rest[i], rest[i + 1]
            bd.put_on(light, dark)


class R047(_Check):
    name = "check-r047"
    description = (
        "If there is a gray block, make it the bottom of a single stack with every other block "
        "stacked on top of it."
    )
    must = ("gray block",)
    min_blocks = 2
    independent = False
    # Without a gray block the rule asks nothing (vacuously satisfied), but it cannot be shown.

    def _gray_chain(self, state, rel=None):
        if "gray block" not in state.positions:
            return None
        rel = rel or relations(state)
        for c in chains(state, rel):
            if c[0] == "gray block":
                return c
        return []

    def satisfied(self, state):
        c = self._gray_chain(state)
        return c is None or len(c) == len(state.blocks)

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        c = self._gray_chain(state)
        n = len(state.blocks)
        return min(len(c) / n, 1 - 0.5 / n)

    def step_moves_away(self, before, after, step):
        if self.score(after) < self.score(before) - 1e-9:
            return True
        c = self._gray_chain(after)
        return c is not None and step.block not in c

    def build(self, bd):
        g = "gray block"
        if bd.rel.below(g) is not None:
            bd.park(g)
        c = chain_of(bd.s, g, bd.rel)
        # keep the blocks already stacked on the gray block
        top = c[-1]
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if b in c:
                continue
            bd.put_on(b, top)
            top = b


class R056(_Check):
    name = "check-r056"
    description = "Never leave a stack of blocks more than two blocks high."
    min_blocks = 3  # with fewer blocks no stack can break the rule
    independent = False

    def block_ok(self, state, rel, b):
        c = chain_of(state, b, rel)
        if c.index(b) >= 2:
            return False
        z = state.positions[b][2]
        base_z = BLOCK_SIZE / 2 + (0.006 if rel.in_bowl(b) else 0.0)
        return z <= base_z + BLOCK_SIZE + 0.02

    def build(self, bd):
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if not self.block_ok(bd.s, bd.rel, b):
                bd.park(b)


class _AllInBowls(_Check):
    min_bowls = 1

    def block_ok(self, state, rel, b):
        return rel.in_bowl(b) is not None

    def build(self, bd):
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if bd.rel.in_bowl(b) is not None:
                continue
            cont = bowl_contents(bd.s, bd.rel)
            w = min(bd.s.bowls, key=lambda w: (len(cont[w]), dist(xy(bd.s, w), xy(bd.s, b))))
            bd.put_in(b, w)


class R064(_AllInBowls):
    name = "check-r064"
    description = "Put every block into a bowl, any bowl, so that no block is left on the table."
    # blocks stacked on a block that is in a bowl count as in that bowl.


class R068(_Check):
    name = "check-r068"
    description = "If there is a blue block and a blue bowl, put the blue block in the blue bowl; the other blocks may stay where they are."
    must = ("blue block", "blue bowl")
    # "Rest can stay where they are" is a permission, not a requirement: other blocks are free.

    def relevant(self, state):
        if "blue block" in state.positions and "blue bowl" in state.positions:
            return ["blue block"]
        return []

    def block_ok(self, state, rel, b):
        return rel.in_bowl(b) == "blue bowl"

    def build(self, bd):
        bd.put_in("blue block", "blue bowl")


class R074(_RegionRule):
    name = "check-r074"
    description = "Keep every block away from the table edges, clustered in the middle of the table."
    # "the middle" = the centre cell of the 3 x 3 table grid (every block at least ~20 cm from each edge)
    box = MIDDLE_CELL

    def prefer(self, state, b):
        return CENTRE


class R080(_RegionRule):
    name = "check-r080"
    description = "Move the gray and brown blocks to the back of the table."
    # back = the back third of the table (y > -0.4); other blocks are free.
    box = BACK_ROW

    def relevant(self, state):
        return [b for b in state.blocks if color(b) in ("gray", "brown")]

    def feasible(self, scene):
        return any(color(b) in ("gray", "brown") for b in scene.blocks)

    def prefer(self, state, b):
        return (xy(state, b)[0], -0.25)


WARM = ("red", "orange", "yellow", "pink", "brown")
COOL = ("blue", "green", "purple", "cyan", "gray")


class R085(_Check):
    name = "check-r085"
    description = (
        "Stack all warm-coloured blocks into one pile on the left half of the table and all "
        "cool-coloured blocks into another pile on the right half."
    )
    # warm = red, orange, yellow, pink, brown; cool = blue, green, purple, cyan, gray
    min_blocks = 2

    @staticmethod
    def group(b):
        return WARM if color(b) in WARM else COOL

    @staticmethod
    def side_ok(group, p):
        return p[0] < 0.0 if group is WARM else p[0] > 0.0

    def block_ok(self, state, rel, b):
        g = self.group(b)
        c = chain_of(state, b, rel)
        return all(color(o) in g for o in c) and self.side_ok(g, xy(state, c[0]))

    def global_ok(self, state, rel):
        cs = chains(state, rel)
        for g in (WARM, COOL):
            members = {b for b in state.blocks if color(b) in g}
            if members and not any(set(c) == members for c in cs):
                return False
        return True

    def build(self, bd):
        for g, box, spot in ((WARM, (-0.28, -0.06, -0.78, -0.22), (-0.2, -0.5)), (COOL, (0.06, 0.28, -0.78, -0.22), (0.2, -0.5))):
            members = [b for b in bd.s.blocks if color(b) in g]
            if not members:
                continue
            rel = bd.rel
            # an existing pure pile on the right side is reused as the base
            cands = [c for c in chains(bd.s, rel) if all(color(o) in g for o in c) and in_box(xy(bd.s, c[0]), box, 0.0)]
            if cands:
                base_chain = max(cands, key=len)
            else:
                base = min(members, key=lambda b: (bd.s.positions[b][2] > BLOCK_SIZE, dist(xy(bd.s, b), spot)))
                bd.place_in_box(base, box, spot, allow_stack=False)
                base_chain = [base]
            bd.done |= set(base_chain)
            top = base_chain[-1]
            for b in sorted(members, key=lambda n: -bd.s.positions[n][2]):
                if b in base_chain:
                    continue
                bd.put_on(b, top)
                top = b
                bd.done.add(b)


class R093(_RegionRule):
    name = "check-r093"
    description = "Put the red block at the left edge of the table."
    # the sister's "side" is not named otherwise; only the red block's place is checked.
    must = ("red block",)
    box = (-0.3, -0.2, -0.8, -0.2)  # block centre within 10 cm of the left edge

    def relevant(self, state):
        return [b for b in state.blocks if color(b) == "red"]

    def prefer(self, state, b):
        return (-0.26, xy(state, b)[1])

    def builders(self, state):
        return [Builder(state)]


class R103(_RegionRule):
    name = "check-r103"
    description = "Keep the right half of the table empty: move every block to the left half."
    # judged on block footprints: centre at least ~1 cm left of the middle line (with tolerance)
    box = (-0.3, -0.02 + TOL, -0.8, -0.2)

    def block_ok(self, state, rel, b):
        return xy(state, b)[0] <= -0.01

    def prefer(self, state, b):
        return (-0.15, xy(state, b)[1])

    def builders(self, state):
        return [Builder(state, park_pred=lambda p: p[0] < -0.04)]

    def build(self, bd):
        for b in sorted(self.relevant(bd.s), key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                continue
            bd.place_in_box(b, (-0.3, -0.02, -0.8, -0.2), self.prefer(bd.s, b))


class R113(_Check):
    name = "check-r113"
    description = (
        "Put exactly one block in each bowl: no bowl holds two blocks, and no bowl stays empty "
        "while a block is available for it."
    )
    min_bowls = 1
    independent = False

    def satisfied(self, state):
        cont = bowl_contents(state)
        if any(len(v) > 1 for v in cont.values()):
            return False
        return sum(len(v) == 1 for v in cont.values()) == min(len(state.blocks), len(state.bowls))

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        cont = bowl_contents(state)
        target = min(len(state.blocks), len(state.bowls))
        if target == 0:
            return 0.0
        s = (sum(len(v) == 1 for v in cont.values()) - 0.5 * sum(len(v) > 1 for v in cont.values())) / target
        return float(min(max(s, 0.0), 1 - 0.5 / target))

    def build(self, bd):
        cont = bowl_contents(bd.s, bd.rel)
        for w, bl in cont.items():
            if len(bl) > 1:
                keep = min(bl, key=lambda b: bd.s.positions[b][2])
                for b in sorted(bl, key=lambda n: -bd.s.positions[n][2]):
                    if b != keep:
                        bd.park(b)
        for w in bd.s.bowls:
            cont = bowl_contents(bd.s, bd.rel)
            if cont[w]:
                continue
            free = [b for b in bd.s.blocks if bd.rel.in_bowl(b) is None]
            if not free:
                break
            b = min(free, key=lambda b: (bd.s.positions[b][2] > BLOCK_SIZE, dist(xy(bd.s, b), xy(bd.s, w))))
            bd.put_in(b, w)


HOT = ("orange", "yellow", "red")
GREEN_BLUE = ("green", "blue")


class R117(_Check):
    name = "check-r117"
    description = (
        "Put all the orange, yellow and red blocks together in one bowl and all the green and "
        "blue blocks together in another bowl; leave the other blocks alone."
    )
    # "Whatever's left stays where it is" cannot be checked without the initial table; it is
    # judged only as: the other blocks are not put into the two group bowls.

    def _groups(self, state):
        hot = [b for b in state.blocks if color(b) in HOT]
        gb = [b for b in state.blocks if color(b) in GREEN_BLUE]
        return hot, gb

    def relevant(self, state):
        h, c = self._groups(state)
        return h + c

    def feasible(self, scene):
        hot = any(color(b) in HOT for b in scene.blocks)
        gb = any(color(b) in GREEN_BLUE for b in scene.blocks)
        return (hot or gb) and len(scene.bowls) >= int(hot) + int(gb)

    def _target_bowls(self, state, rel):
        cont = bowl_contents(state, rel)
        out = {}
        for grp, cols in (("hot", HOT), ("gb", GREEN_BLUE)):
            counts = {w: sum(color(b) in cols for b in v) for w, v in cont.items()}
            best = max(counts, key=lambda w: counts[w], default=None)
            out[grp] = best if best is not None and counts[best] > 0 else None
        return out, cont

    def block_ok(self, state, rel, b):
        tb, cont = self._target_bowls(state, rel)
        grp, cols = ("hot", HOT) if color(b) in HOT else ("gb", GREEN_BLUE)
        w = tb[grp]
        if w is None or rel.in_bowl(b) != w:
            return False
        other = tb["gb" if grp == "hot" else "hot"]
        if other == w:
            return False
        return all(color(o) in cols for o in cont[w])

    def build(self, bd):
        hot, gb = self._groups(bd.s)
        rel = bd.rel
        cont = bowl_contents(bd.s, rel)
        groups = [(g, cols) for g, cols in ((hot, HOT), (gb, GREEN_BLUE)) if g]
        best, best_cost = None, None
        for ws in itertools.permutations(bd.s.bowls, len(groups)):
            cost = 0
            for (g, cols), w in zip(groups, ws):
                cost += sum(rel.in_bowl(b) != w for b in g) + 2 * sum(color(o) not in cols for o in cont[w])
            if best_cost is None or cost < best_cost:
                best, best_cost = ws, cost
        if best is None:
            raise PlanFail("not enough bowls")
        for (g, cols), w in zip(groups, best):
            for o in sorted(bowl_contents(bd.s, bd.rel)[w], key=lambda n: -bd.s.positions[n][2]):
                if color(o) not in cols:
                    bd.park(o)
        for (g, cols), w in zip(groups, best):
            for b in sorted(g, key=lambda n: -bd.s.positions[n][2]):
                if bd.rel.in_bowl(b) != w:
                    bd.put_in(b, w)


class R121(_NextToMatchingBowl):
    name = "check-r121"
    description = "Place every block right next to the bowl of its own colour, not inside it."


class R124(_Check):
    name = "check-r124"
    description = "Put every block into a bowl whose colour is different from the block's colour."
    min_bowls = 1

    def feasible(self, scene):
        return bool(scene.blocks) and all(
            any(color(w) != color(b) for w in scene.bowls) for b in scene.blocks
        )

    def block_ok(self, state, rel, b):
        w = rel.in_bowl(b)
        return w is not None and color(w) != color(b)

    def build(self, bd):
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                continue
            cont = bowl_contents(bd.s, bd.rel)
            ws = [w for w in bd.s.bowls if color(w) != color(b)]
            if not ws:
                raise PlanFail("no other-coloured bowl")
            w = min(ws, key=lambda w: (len(cont[w]), dist(xy(bd.s, w), xy(bd.s, b))))
            bd.put_in(b, w)


class _OnTop(_Check):
    """upper block directly on lower block; the other blocks are free."""

    upper = ""
    lower = ""
    independent = False

    @property
    def must(self):
        return (self.upper, self.lower)

    def relevant(self, state):
        return [self.upper] if self.upper in state.positions and self.lower in state.positions else []

    def block_ok(self, state, rel, b):
        return rel.below(self.upper) == self.lower

    def step_moves_away(self, before, after, step):
        if self.score(after) < self.score(before) - 1e-9:
            return True
        rel = relations(after)
        if step.block == self.upper and rel.below(self.upper) != self.lower:
            return True
        return step.block == self.lower and rel.below(self.lower) == self.upper

    def build(self, bd):
        bd.put_on(self.upper, self.lower)


class R143(_OnTop):
    name = "check-r143"
    description = "Put the yellow block on top of the green block; the other blocks can go anywhere sensible."
    upper, lower = "yellow block", "green block"
    # "The rest can go wherever's sensible" puts no checkable constraint on the other blocks.


class R145(_AllInBowls):
    name = "check-r145"
    description = "Put all the blocks into the bowls, in any bowls."


class R149(_Tower):
    name = "check-r149"
    description = "Stack all the blocks into one single tall tower."
    # the tower may stand anywhere (also in a bowl); "one big tower" = every block in it.

    def base_spot(self, bd):
        rel = bd.rel
        clear_blocks = [b for b in bd.s.blocks if rel.above(b) is None]
        return "block", min(clear_blocks, key=lambda b: bd.s.positions[b][2])


class R150(_NextToMatchingBowl):
    name = "check-r150"
    description = "Place every block next to the bowl of its own colour (beside it, not in it)."
    # blocks without a bowl of their colour are free (the rule says nothing about them).


class R162(_OnTop):
    name = "check-r162"
    description = "Put the yellow block directly on top of the brown block; the other blocks can go anywhere tidy."
    upper, lower = "yellow block", "brown block"
    # "Whatever's tidiest" for the other blocks is not checkable on the final table: dropped.


class R164(_RegionRule):
    name = "check-r164"
    description = "Keep the left half of the table empty: move every block to the right of the middle."
    box = (0.02 - TOL, 0.3, -0.8, -0.2)

    def block_ok(self, state, rel, b):
        return xy(state, b)[0] >= 0.01

    def prefer(self, state, b):
        return (0.15, xy(state, b)[1])

    def builders(self, state):
        return [Builder(state, park_pred=lambda p: p[0] > 0.04)]

    def build(self, bd):
        for b in sorted(self.relevant(bd.s), key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                continue
            bd.place_in_box(b, (0.02, 0.3, -0.8, -0.2), self.prefer(bd.s, b))


class R168(_Check):
    name = "check-r168"
    description = (
        "Put the brightest block (the yellow one, else the orange one, else the lightest-coloured "
        "block) at the very centre of the table."
    )
    CENTRE_TOL = 0.035

    @staticmethod
    def candidates(state) -> list[str]:
        cols = {color(b): b for b in state.blocks}
        if "yellow" in cols:
            return [cols["yellow"]]
        if "orange" in cols:
            return [cols["orange"]]
        if not cols:
            return []
        # no yellow/orange: "brightest" by luminance; near-ties (< 0.04) are all accepted
        top = max(luminance(c) for c in cols)
        return sorted((b for c, b in cols.items() if luminance(c) >= top - 0.04), key=lambda b: -luminance(color(b)))

    def satisfied(self, state):
        w = centre_bowl(state)
        rel = relations(state)
        return any(
            dist(xy(state, b), CENTRE) <= self.CENTRE_TOL or (w is not None and rel.in_bowl(b) == w)
            for b in self.candidates(state)
        )

    def score(self, state):
        return 1.0 if self.satisfied(state) else 0.0

    def step_moves_away(self, before, after, step):
        if self.score(after) < self.score(before) - 1e-9:
            return True
        return step.block in self.candidates(after) and not self.satisfied(after)

    def build(self, bd):
        b = self.candidates(bd.s)[0]
        w = centre_bowl(bd.s)
        if w is not None:
            bd.put_in(b, w)
            return
        p = bd.find(b, (-0.025, 0.025, -0.525, -0.475), CENTRE, step=0.005)
        if p is not None:
            bd.put_at(b, p)
            return
        bd.put_at(b, CENTRE)


class R172(_Check):
    name = "check-r172"
    description = (
        "Put the red block on the left side of the table, the blue block on the right side, "
        "and every other block in the middle column."
    )

    def feasible(self, scene):
        return any(color(b) in ("red", "blue") for b in scene.blocks)

    @staticmethod
    def box_for(b):
        return {"red": LEFT_COL, "blue": RIGHT_COL}.get(color(b), MID_COL)

    def block_ok(self, state, rel, b):
        return in_box(xy(state, b), self.box_for(b), 0.01)

    def build(self, bd):
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                bd.done.add(b)
        for b in sorted(bd.s.blocks, key=lambda n: -bd.s.positions[n][2]):
            if self.block_ok(bd.s, bd.rel, b):
                continue
            box = self.box_for(b)
            prefer = {"red": (-0.22, xy(bd.s, b)[1]), "blue": (0.22, xy(bd.s, b)[1])}.get(color(b), (0.0, xy(bd.s, b)[1]))
            bd.place_in_box(b, box, prefer, margin=0.03)
            bd.done.add(b)


class R184(_RegionRule):
    name = "check-r184"
    description = "Keep the front of the table clear by moving every block to the back edge of the table."
    box = (-0.3, 0.3, -0.32, -0.2)  # block centre within ~12 cm of the back edge

    def prefer(self, state, b):
        return (xy(state, b)[0], -0.25)

    def builders(self, state):
        return [Builder(state)]


class R189(_NextToMatchingBowl):
    name = "check-r189"
    description = "Place every block directly in front of the bowl of its own colour, not inside it."
    side = "front"

    def direction_ok(self, d):
        return d[1] < -0.03 and abs(d[0]) <= -d[1]


ALL = [
    R001, R012, R030, R035, R037, R039, R040, R047, R056, R064, R068, R074, R080, R085, R093,
    R103, R113, R117, R121, R124, R143, R145, R149, R150, R162, R164, R168, R172, R184, R189,
]
