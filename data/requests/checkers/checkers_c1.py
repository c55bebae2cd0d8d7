"""Checkers for the requests of requests_c1.jsonl.

Each class judges a final table (``satisfied``/``score``), says whether a scene can show the
request (``feasible``), samples such scenes and plans a way to a satisfying table under the
symbolic world model (``activeintent.world.apply_skill``).
"""

from __future__ import annotations

import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_RADIUS,
    COLOR_NAMES,
    COLORS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    WorldState,
    apply_skill,
    relations,
)
from activeintent.world import sample_scene as _world_sample_scene

(X0, X1), (Y0, Y1) = BOUNDS
HALF = BLOCK_SIZE / 2
NOISE = 0.01  # settling noise allowed by every judgement
MAX_ITER = 60


# --------------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------------


def _kind(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


def _color(name: str) -> str:
    return name.split(" ", 1)[0]


def _radius(name: str) -> float:
    return BOWL_RADIUS if _kind(name) == "bowl" else HALF


def _blocks(state: WorldState) -> list[str]:
    return [n for n in state.positions if _kind(n) == "block"]


def _bowls(state: WorldState) -> list[str]:
    return [n for n in state.positions if _kind(n) == "bowl"]


def _xy(state: WorldState, name: str) -> tuple[float, float]:
    p = state.positions[name]
    return float(p[0]), float(p[1])


def _dist(state: WorldState, a: str, b: str) -> float:
    pa, pb = state.positions[a], state.positions[b]
    return math.hypot(pa[0] - pb[0], pa[1] - pb[1])


def _top(rel, block: str) -> str:
    while (a := rel.above(block)) is not None:
        block = a
    return block


def _base(rel, block: str) -> str:
    seen = {block}
    while (b := rel.below(block)) is not None and b not in seen:
        seen.add(b)
        block = b
    return block


def _chain(rel, base: str) -> list[str]:
    out, seen = [base], {base}
    while (a := rel.above(out[-1])) is not None and a not in seen:
        seen.add(a)
        out.append(a)
    return out


def _stacks(state: WorldState) -> list[list[str]]:
    """Stacks of blocks (bottom first), singles included."""
    rel = relations(state)
    bases = [b for b in _blocks(state) if rel.below(b) is None]
    return [_chain(rel, b) for b in bases]


def _sorted_bowls_lr(state: WorldState) -> list[str]:
    return sorted(_bowls(state), key=lambda w: (state.positions[w][0], w))


def _edge_distance(x: float, y: float) -> float:
    return min(x - X0, X1 - x, y - Y0, Y1 - y)


class _Sim:
    """A plan under construction: the predicted state and the steps that reached it."""

    def __init__(self, state: WorldState):
        self.state = state
        self.steps: list = []

    @property
    def rel(self):
        return relations(self.state)

    def do(self, step) -> bool:
        new, fail = apply_skill(self.state, step)
        if fail is not None:
            return False
        self.state = new
        self.steps.append(step)
        return True


_GX = np.round(np.arange(X0 + 0.03, X1 - 0.03 + 1e-9, 0.01), 4)
_GY = np.round(np.arange(Y0 + 0.03, Y1 - 0.03 + 1e-9, 0.01), 4)
_GRID = np.array([(x, y) for x in _GX for y in _GY])  # block centres at least 3 cm inside the table


def _clearances(state: WorldState, pts: np.ndarray, moving: str) -> np.ndarray:
    """For each point: the smallest gap between a block placed there and another footprint."""
    best = np.full(len(pts), np.inf)
    for o, p in state.positions.items():
        if o == moving:
            continue
        if _kind(o) == "block" and p[2] > BLOCK_SIZE:  # stacked: its base counts
            continue
        d = np.hypot(pts[:, 0] - p[0], pts[:, 1] - p[1]) - _radius(o) - HALF
        best = np.minimum(best, d)
    return best


def _find_spot(state, moving, accept=None, key=None, min_clear=0.015, pts=None):
    """A free table point for ``moving`` (preferring a comfortable clearance, then ``key``)."""
    pts = _GRID if pts is None else np.asarray(pts, dtype=float)
    if len(pts) == 0:
        return None
    if accept is not None:
        mask = np.array([bool(accept(float(x), float(y))) for x, y in pts])
        pts = pts[mask]
        if len(pts) == 0:
            return None
    clear = _clearances(state, pts, moving)
    ok = clear >= 0.006
    if not ok.any():
        return None
    pts, clear = pts[ok], clear[ok]
    keys = np.array([key(float(x), float(y)) for x, y in pts]) if key is not None else np.zeros(len(pts))
    order = sorted(range(len(pts)), key=lambda i: (clear[i] < min_clear, keys[i], -clear[i]))
    i = order[0]
    return (round(float(pts[i][0]), 4), round(float(pts[i][1]), 4))


def _move_to_spot(sim: _Sim, block: str, accept=None, key=None, pts=None) -> bool:
    for min_clear in (0.015, 0.006):
        spot = _find_spot(sim.state, block, accept=accept, key=key, min_clear=min_clear, pts=pts)
        if spot is None:
            return False
        if sim.do(PutAt(block=block, position=spot)):
            return True
    return False


def _park(sim: _Sim, block: str, near: tuple[float, float] | None = None, accept=None) -> bool:
    """Put ``block`` on a free table spot (out of every bowl), near ``near`` if given."""
    if near is None:
        near = _xy(sim.state, block)
    return _move_to_spot(sim, block, accept=accept, key=lambda x, y: math.hypot(x - near[0], y - near[1]))


def _ring(center: tuple[float, float], radius: float, n: int = 24) -> np.ndarray:
    ang = np.arange(n) * 2 * np.pi / n
    return np.stack([center[0] + radius * np.cos(ang), center[1] + radius * np.sin(ang)], axis=1)


def _in_table(x: float, y: float, margin: float = 0.025) -> bool:
    return X0 + margin <= x <= X1 - margin and Y0 + margin <= y <= Y1 - margin


def _finish(intention: Intention, sim: _Sim):
    return list(sim.steps) if intention.satisfied(sim.state) else None


def _solve_per_block(intention, state, is_bad, move, park_key=None):
    """Generic loop: move a misplaced block that nothing rests on; when every misplaced block
    is covered, park the top of one of their stacks first."""
    sim = _Sim(state)
    failed: set[str] = set()
    for _ in range(MAX_ITER):
        rel = sim.rel
        bad = [b for b in _blocks(sim.state) if is_bad(sim.state, rel, b)]
        if not bad:
            return _finish(intention, sim)
        progressed = False
        for b in bad:
            if rel.above(b) is None and b not in failed:
                if move(sim, b):
                    progressed = True
                    failed.clear()
                    break
                failed.add(b)
        if progressed:
            continue
        for b in bad:
            if rel.above(b) is not None:
                t = _top(rel, b)
                if _park(sim, t, accept=park_key):
                    progressed = True
                    failed.clear()
                    break
        if not progressed:
            return None
    return _finish(intention, sim)


# --------------------------------------------------------------------------------------------
# r018: blocks to the back edge
# --------------------------------------------------------------------------------------------


class R018(Intention):
    name = "r018"
    description = "Just tidy all the blocks to the back edge so there's room at the front for homework."

    BACK = -0.35  # block centres behind this line (the back ~15 cm of the table)

    def _ok(self, state, b, slack=0.0):
        return state.positions[b][1] >= self.BACK + slack

    def satisfied(self, state):
        return all(self._ok(state, b) for b in _blocks(state))

    def score(self, state):
        bl = _blocks(state)
        return 1.0 if not bl else sum(self._ok(state, b) for b in bl) / len(bl)

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _world_sample_scene(rng)

    def plan(self, state):
        if self.satisfied(state):
            return []

        def bad(s, rel, b):
            return not self._ok(s, b, slack=0.005)

        def move(sim, b):
            bx, _ = _xy(sim.state, b)
            if _move_to_spot(
                sim, b, accept=lambda x, y: y >= -0.31, key=lambda x, y: 2 * abs(y + 0.25) + 0.3 * abs(x - bx)
            ):
                return True
            rel = sim.rel
            for o in sorted(_blocks(sim.state), key=lambda o: -sim.state.positions[o][1]):
                if o != b and _base(rel, o) != b and sim.state.positions[o][1] >= -0.32:
                    if sim.do(PutOn(block=b, target=_top(rel, o))):
                        return True
            for w in _bowls(sim.state):
                if sim.state.positions[w][1] >= -0.33 and sim.do(PutIn(block=b, bowl=w)):
                    return True
            return False

        return _solve_per_block(self, state, bad, move, park_key=lambda x, y: y >= -0.31)


# --------------------------------------------------------------------------------------------
# r062: fill the bowls from left to right, one block each
# --------------------------------------------------------------------------------------------


class R062(Intention):
    name = "r062"
    description = "Fill the bowls from left to right, one block each, and don't skip any bowl."

    def _wants(self, state):
        bowls = _sorted_bowls_lr(state)
        k = min(len(_blocks(state)), len(bowls))
        return bowls, [1 if i < k else 0 for i in range(len(bowls))]

    def _counts(self, state):
        rel = relations(state)
        counts = {w: 0 for w in _bowls(state)}
        for b, w in rel.inside:
            counts[w] += 1
        return counts

    def satisfied(self, state):
        bowls, want = self._wants(state)
        counts = self._counts(state)
        return all(counts[w] == n for w, n in zip(bowls, want))

    def score(self, state):
        bowls, want = self._wants(state)
        if not bowls:
            return 1.0
        counts = self._counts(state)
        return sum(counts[w] == n for w, n in zip(bowls, want)) / len(bowls)

    def feasible(self, scene):
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        nw = int(rng.integers(2, 4))
        nb = int(rng.integers(max(1, 3 - nw), 5 - nw + 1))
        return _world_sample_scene(rng, n_blocks=nb, n_bowls=nw)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(MAX_ITER):
            if self.satisfied(sim.state):
                return list(sim.steps)
            bowls, want = self._wants(sim.state)
            counts = self._counts(sim.state)
            rel = sim.rel
            over = [w for w, n in zip(bowls, want) if counts[w] > n]
            if over:
                w = over[0]
                inside = [b for b, ww in rel.inside if ww == w]
                top = max(inside, key=lambda b: sim.state.positions[b][2])
                if not _park(sim, top, near=_xy(sim.state, w)):
                    return None
                continue
            under = [w for w, n in zip(bowls, want) if counts[w] < n]
            w = under[0]
            free = [b for b in _blocks(sim.state) if rel.in_bowl(b) is None and rel.above(b) is None]
            if not free:
                return None
            free.sort(key=lambda b: _dist(sim.state, b, w))
            if not any(sim.do(PutIn(block=b, bowl=w)) for b in free):
                return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# r086: every block in a bowl
# --------------------------------------------------------------------------------------------


class R086(Intention):
    name = "r086"
    description = "Just put all the blocks in bowls so the cat has nothing to bat around. Honestly that's it."

    def satisfied(self, state):
        rel = relations(state)
        return all(rel.in_bowl(b) is not None for b in _blocks(state))

    def score(self, state):
        bl = _blocks(state)
        if not bl:
            return 1.0
        rel = relations(state)
        return sum(rel.in_bowl(b) is not None for b in bl) / len(bl)

    def feasible(self, scene):
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _world_sample_scene(rng)

    def plan(self, state):
        if self.satisfied(state):
            return []
        if not _bowls(state):
            return None

        def bad(s, rel, b):
            return rel.in_bowl(b) is None

        def move(sim, b):
            rel = sim.rel
            counts = {w: 0 for w in _bowls(sim.state)}
            for _, w in rel.inside:
                counts[w] += 1
            for w in sorted(counts, key=lambda w: (counts[w], _dist(sim.state, b, w))):
                if sim.do(PutIn(block=b, bowl=w)):
                    return True
            return False

        return _solve_per_block(self, state, bad, move)


# --------------------------------------------------------------------------------------------
# r114: everything on the left side
# --------------------------------------------------------------------------------------------


class R114(Intention):
    name = "r114"
    description = (
        "Everything on the left side of the table. I'm right-handed and I need my right side free to work."
    )

    LEFT = -0.01  # block centres left of this (the left half, with a block's worth of doubt)

    def _ok(self, state, b, slack=0.0):
        return state.positions[b][0] <= self.LEFT - slack

    def satisfied(self, state):
        return all(self._ok(state, b) for b in _blocks(state))

    def score(self, state):
        bl = _blocks(state)
        return 1.0 if not bl else sum(self._ok(state, b) for b in bl) / len(bl)

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _world_sample_scene(rng)

    def plan(self, state):
        if self.satisfied(state):
            return []

        def bad(s, rel, b):
            return not self._ok(s, b, slack=0.005)

        def move(sim, b):
            bx, by = _xy(sim.state, b)
            if _move_to_spot(
                sim, b, accept=lambda x, y: x <= -0.06, key=lambda x, y: math.hypot(x + 0.12, y - by)
            ):
                return True
            rel = sim.rel
            for o in sorted(_blocks(sim.state), key=lambda o: sim.state.positions[o][0]):
                if o != b and _base(rel, o) != b and sim.state.positions[o][0] <= -0.04:
                    if sim.do(PutOn(block=b, target=_top(rel, o))):
                        return True
            for w in _bowls(sim.state):
                if sim.state.positions[w][0] <= -0.04 and sim.do(PutIn(block=b, bowl=w)):
                    return True
            return False

        return _solve_per_block(self, state, bad, move, park_key=lambda x, y: x <= -0.06)


# --------------------------------------------------------------------------------------------
# r171: each block next to (not in) the bowl of its colour
# --------------------------------------------------------------------------------------------


def _beside_bowl(state, rel, block, bowl, max_gap=0.05 + NOISE) -> bool:
    """On the table (not in any bowl) with its footprint within ``max_gap`` of the bowl's rim."""
    if rel.in_bowl(block) is not None:
        return False
    return _dist(state, block, bowl) - BOWL_RADIUS - HALF <= max_gap


def _put_beside(sim: _Sim, block: str, target: str) -> bool:
    """Next to ``target`` (its nearest free side, else any free point round it)."""
    if sim.do(PutNextTo(block=block, target=target, side="nearest")):
        return True
    here = _xy(sim.state, block)
    for r in (_radius(target) + HALF + 0.014, _radius(target) + HALF + 0.025):
        pts = [p for p in _ring(_xy(sim.state, target), r, 36) if _in_table(*p)]
        if _move_to_spot(sim, block, key=lambda x, y: math.hypot(x - here[0], y - here[1]), pts=pts):
            return True
    return False


class R171(Intention):
    name = "r171"
    description = (
        "Put each block next to the bowl of the same colour but not in it, so I can practise the final "
        "placement with my client."
    )

    def _targets(self, names):
        return [(b, f"{_color(b)} bowl") for b in names if _kind(b) == "block" and f"{_color(b)} bowl" in names]

    def satisfied(self, state):
        rel = relations(state)
        return all(_beside_bowl(state, rel, b, w) for b, w in self._targets(list(state.positions)))

    def score(self, state):
        t = self._targets(list(state.positions))
        if not t:
            return 1.0
        rel = relations(state)
        return sum(_beside_bowl(state, rel, b, w) for b, w in t) / len(t)

    def feasible(self, scene):
        return bool(self._targets(list(scene.objects)))

    def sample_scene(self, rng):
        while True:
            scene = _world_sample_scene(rng, matching=True)
            if self.feasible(scene):
                return scene

    def plan(self, state):
        if self.satisfied(state):
            return []
        names = list(state.positions)
        target = dict(self._targets(names))

        def bad(s, rel, b):
            return b in target and not _beside_bowl(s, rel, b, target[b], max_gap=0.045)

        def move(sim, b):
            return _put_beside(sim, b, target[b])

        return _solve_per_block(self, state, bad, move)


# --------------------------------------------------------------------------------------------
# r235: complementary colours together
# --------------------------------------------------------------------------------------------

COMPLEMENTS = (("orange", "blue"), ("red", "green"), ("yellow", "purple"))


def _complement_pairs(names) -> list[tuple[str, str, str]]:
    """(kind, block, partner): 'bb' two blocks; 'bw' a block and its complement's bowl."""
    names = set(names)
    out = []
    for c1, c2 in COMPLEMENTS:
        b1, b2, w1, w2 = f"{c1} block", f"{c2} block", f"{c1} bowl", f"{c2} bowl"
        if b1 in names and b2 in names:
            out.append(("bb", b1, b2))
        elif b1 in names and w2 in names:
            out.append(("bw", b1, w2))
        elif b2 in names and w1 in names:
            out.append(("bw", b2, w1))
    return out


def _blocks_together(state, rel, a, b, max_dist=0.09 + 0.005) -> bool:
    if rel.below(a) == b or rel.below(b) == a:
        return True
    ia, ib = rel.in_bowl(a), rel.in_bowl(b)
    if (ia is None) != (ib is None):
        return False
    pa, pb = state.positions[a], state.positions[b]
    if abs(pa[2] - pb[2]) > 0.015:
        return False
    return _dist(state, a, b) <= max_dist


class R235(Intention):
    name = "r235"
    description = (
        "complementary colours together pls. orange next to blue, red next to green, yellow next to "
        "purple. whatever pairs show up that day"
    )

    def _pair_ok(self, state, rel, pair, strict=False):
        kind, a, b = pair
        if kind == "bb":
            return _blocks_together(state, rel, a, b, max_dist=0.08 if strict else 0.095)
        if rel.in_bowl(a) == b:
            return True
        return _beside_bowl(state, rel, a, b, max_gap=0.045 if strict else 0.06)

    def satisfied(self, state):
        rel = relations(state)
        return all(self._pair_ok(state, rel, p) for p in _complement_pairs(state.positions))

    def score(self, state):
        pairs = _complement_pairs(state.positions)
        if not pairs:
            return 1.0
        rel = relations(state)
        return sum(self._pair_ok(state, rel, p) for p in pairs) / len(pairs)

    def feasible(self, scene):
        return bool(_complement_pairs(scene.objects))

    def sample_scene(self, rng):
        c1, c2 = COMPLEMENTS[int(rng.integers(len(COMPLEMENTS)))]
        if rng.random() < 0.5:
            c1, c2 = c2, c1
        objs = [f"{c1} block", f"{c2} block"] if rng.random() < 0.75 else [f"{c1} block", f"{c2} bowl"]
        pool = [f"{c} {k}" for c in COLOR_NAMES for k in ("block", "bowl") if f"{c} {k}" not in objs]
        extra = int(rng.integers(1, 4))
        while len(objs) < 2 + extra:
            o = pool[int(rng.integers(len(pool)))]
            if o in objs or (_kind(o) == "bowl" and sum(_kind(x) == "bowl" for x in objs) >= 2):
                continue
            objs.append(o)
        order = rng.permutation(len(objs))
        return Scene(objects=[objs[i] for i in order])

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        pairs = _complement_pairs(state.positions)
        for _ in range(MAX_ITER):
            rel = sim.rel
            todo = [p for p in pairs if not self._pair_ok(sim.state, rel, p, strict=True)]
            if not todo:
                return _finish(self, sim)
            if not self._fix(sim, todo[0]):
                return None
        return _finish(self, sim)

    def _fix(self, sim: _Sim, pair) -> bool:
        kind, a, b = pair
        rel = sim.rel
        if kind == "bw":
            if rel.above(a) is not None:
                return _park(sim, _top(rel, a))
            return _put_beside(sim, a, b) or sim.do(PutIn(block=a, bowl=b))

        def anchored(x):  # standing on the table itself: a good anchor
            return x in rel.on_table and rel.below(x) is None

        options = sorted([(a, b), (b, a)], key=lambda mb: (not anchored(mb[1]), rel.above(mb[0]) is not None))
        for mover, anchor in options:
            if rel.above(mover) is not None or not anchored(anchor):
                continue
            if sim.do(PutNextTo(block=mover, target=anchor, side="nearest")):
                return True
            here = _xy(sim.state, mover)
            pts = [p for p in _ring(_xy(sim.state, anchor), 0.054, 24) if _in_table(*p)]
            if _move_to_spot(sim, mover, key=lambda x, y: math.hypot(x - here[0], y - here[1]), pts=pts):
                return True
        # no usable anchor/mover: free one of them first
        for x in (a, b):
            if rel.above(x) is not None:
                return _park(sim, _top(rel, x))
        for x in (a, b):
            if not anchored(x):
                return _park(sim, x)
        # both anchored but no room round either: stack them
        return sim.do(PutOn(block=a, target=b)) or sim.do(PutOn(block=b, target=a))


# --------------------------------------------------------------------------------------------
# r256: red block alone in the rightmost bowl
# --------------------------------------------------------------------------------------------


class R256(Intention):
    name = "r256"
    description = (
        "Red block always goes in a bowl on its own, the one furthest to the right. Treat it like a "
        "biohazard bag."
    )
    RED = "red block"

    def _parts(self, state):
        rel = relations(state)
        bowls = _sorted_bowls_lr(state)
        if not bowls:
            return False, False
        w = bowls[-1]
        inside = [b for b, ww in rel.inside if ww == w]
        return self.RED in inside, all(b == self.RED for b in inside)

    def satisfied(self, state):
        if self.RED not in state.positions:
            return True
        red_in, alone = self._parts(state)
        return red_in and alone

    def score(self, state):
        if self.RED not in state.positions:
            return 1.0
        red_in, alone = self._parts(state)
        return 0.5 * red_in + 0.5 * (red_in and alone)

    def feasible(self, scene):
        return self.RED in scene.objects and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        nw = int(rng.integers(1, 4))
        total = int(rng.integers(max(3, 2 + nw), 6))
        nb_other = total - 1 - nw
        others = [c for c in COLOR_NAMES if c != "red"]
        bcols = list(rng.choice(others, size=nb_other, replace=False))
        wcols = list(rng.choice(COLOR_NAMES, size=nw, replace=False))
        objs = ["red block"] + [f"{c} block" for c in bcols] + [f"{c} bowl" for c in wcols]
        order = rng.permutation(len(objs))
        return Scene(objects=[objs[i] for i in order])

    def plan(self, state):
        if self.satisfied(state):
            return []
        if not _bowls(state):
            return None
        sim = _Sim(state)
        w = _sorted_bowls_lr(state)[-1]
        wxy = _xy(state, w)
        # empty the bowl of everything but the red block (red too if something else is under it)
        for _ in range(MAX_ITER):
            rel = sim.rel
            inside = [b for b, ww in rel.inside if ww == w]
            others = [b for b in inside if b != self.RED]
            if not others:
                break
            top = max(inside, key=lambda b: sim.state.positions[b][2])
            if not (_put_beside(sim, top, w) or _park(sim, top, near=wxy)):
                return None
        for _ in range(MAX_ITER):
            rel = sim.rel
            if rel.in_bowl(self.RED) == w or rel.above(self.RED) is None:
                break
            if not _park(sim, _top(rel, self.RED)):
                return None
        rel = sim.rel
        if rel.in_bowl(self.RED) != w and not sim.do(PutIn(block=self.RED, bowl=w)):
            return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# r323: red block in front of everything else
# --------------------------------------------------------------------------------------------


class R323(Intention):
    name = "r323"
    description = (
        "Just put the red one in front of everything else. Red's my race-day colour, first thing I want to see."
    )
    RED = "red block"

    @staticmethod
    def _margin(other: str, plan: bool = False) -> float:
        # how much nearer the person (smaller y) the red block's centre must be than the other's:
        # half a block ahead of a block; for a bowl, the red's front face level with its front rim
        if _kind(other) == "block":
            return 0.04 if plan else 0.02
        return 0.06 if plan else BOWL_RADIUS - HALF

    def _ahead(self, state, o, plan=False):
        return state.positions[o][1] - state.positions[self.RED][1] >= self._margin(o, plan)

    def satisfied(self, state):
        if self.RED not in state.positions:
            return True
        return all(self._ahead(state, o) for o in state.positions if o != self.RED)

    def score(self, state):
        if self.RED not in state.positions:
            return 1.0
        others = [o for o in state.positions if o != self.RED]
        return 1.0 if not others else sum(self._ahead(state, o) for o in others) / len(others)

    def feasible(self, scene):
        return self.RED in scene.objects and len(scene.objects) >= 2

    def sample_scene(self, rng):
        n = int(rng.integers(3, 6))
        pool = [o for o in (f"{c} {k}" for c in COLOR_NAMES for k in ("block", "bowl")) if o != self.RED]
        objs = [self.RED]
        while len(objs) < n:
            o = pool[int(rng.integers(len(pool)))]
            if o in objs or (_kind(o) == "bowl" and sum(_kind(x) == "bowl" for x in objs) >= 2):
                continue
            objs.append(o)
        order = rng.permutation(len(objs))
        return Scene(objects=[objs[i] for i in order])

    LOWEST = -0.775  # the red block's centre may come this near the front edge

    def plan(self, state):
        if self.RED not in state.positions:
            return []
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(MAX_ITER):
            rel = sim.rel
            if rel.above(self.RED) is None:
                break
            if not _park(sim, _top(rel, self.RED), accept=lambda x, y: y >= -0.65):
                return None
        # other blocks crowding the front edge go back a little
        for _ in range(MAX_ITER):
            rel = sim.rel
            crowd = [
                o
                for o in _blocks(sim.state)
                if o != self.RED and _base(rel, o) != self.RED
                and sim.state.positions[o][1] - self._margin(o, True) < self.LOWEST
            ]
            if not crowd:
                break
            o = next((o for o in crowd if rel.above(o) is None), None)
            if o is None:
                return None
            ox, oy = _xy(sim.state, o)
            if not _move_to_spot(
                sim, o, accept=lambda x, y: y >= -0.68, key=lambda x, y: math.hypot(x - ox, y - oy)
            ):
                return None
        others = [o for o in sim.state.positions if o != self.RED]
        limit = min(sim.state.positions[o][1] - self._margin(o, True) for o in others)
        limit = min(limit, -0.74)
        rx, _ = _xy(sim.state, self.RED)
        ok = _move_to_spot(
            sim,
            self.RED,
            accept=lambda x, y: self.LOWEST - 1e-9 <= y <= limit + 1e-9,
            key=lambda x, y: abs(y - limit) + 0.3 * abs(x - rx),
            pts=[(x, y) for x in _GX for y in np.round(np.arange(-0.775, -0.6, 0.005), 4)],
        )
        if not ok:
            return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# r033: out of wrong-coloured bowls, set beside them
# --------------------------------------------------------------------------------------------


class R033(Intention):
    name = "r033"
    description = (
        "Leave the blocks where they are unless they're in a bowl that's the wrong colour. Then take them out "
        "and put them beside it."
    )

    @staticmethod
    def _wrong(rel, b):
        w = rel.in_bowl(b)
        return w is not None and _color(w) != _color(b)

    def satisfied(self, state):
        rel = relations(state)
        return not any(self._wrong(rel, b) for b in _blocks(state))

    def score(self, state):
        bl = _blocks(state)
        if not bl:
            return 1.0
        rel = relations(state)
        return sum(not self._wrong(rel, b) for b in bl) / len(bl)

    def feasible(self, scene):
        return any(_color(b) != _color(w) for b in scene.blocks for w in scene.bowls)

    def sample_scene(self, rng):
        while True:
            scene = _world_sample_scene(rng)
            if self.feasible(scene):
                return scene

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        put_back: list[tuple[str, str]] = []  # right-coloured blocks lifted off a wrong one
        for _ in range(MAX_ITER):
            rel = sim.rel
            wrong = [b for b in _blocks(sim.state) if self._wrong(rel, b)]
            if not wrong:
                break
            b = next((b for b in wrong if rel.above(b) is None), None)
            if b is not None:
                w = rel.in_bowl(b)
                if not (_put_beside(sim, b, w) or _park(sim, b, near=_xy(sim.state, w))):
                    return None
                continue
            t = _top(rel, wrong[0])
            w = rel.in_bowl(t)
            if not (_put_beside(sim, t, w) or _park(sim, t, near=_xy(sim.state, w))):
                return None
            put_back.append((t, w))
        for t, w in reversed(put_back):
            if relations(sim.state).above(t) is None and not sim.do(PutIn(block=t, bowl=w)):
                return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# r129: into the matching bowl, else directly right of the nearest bowl
# --------------------------------------------------------------------------------------------


class R129(Intention):
    name = "r129"
    description = (
        "Every block should end up in the bowl matching its colour. Where no such bowl exists, put the block "
        "directly to the right of the nearest bowl."
    )
    RIGHT_X = BOWL_RADIUS + HALF + 0.012  # centre offset of a block set right of a bowl
    TIE = 0.025

    @staticmethod
    def _nearest_bowl(state, b):
        bowls = _bowls(state)
        return min(bowls, key=lambda w: _dist(state, b, w)) if bowls else None

    def _right_of(self, state, rel, b, w, tol=NOISE):
        if rel.in_bowl(b) is not None:
            return False
        (bx, by), (wx, wy) = _xy(state, b), _xy(state, w)
        dx, dy = bx - wx, by - wy
        gap = math.hypot(dx, dy) - BOWL_RADIUS - HALF
        return dx >= BOWL_RADIUS - tol and abs(dy) <= 0.055 + tol and gap <= 0.05 + tol

    def _ok(self, state, rel, b, tol=NOISE):
        own = f"{_color(b)} bowl"
        if own in state.positions:
            return rel.in_bowl(b) == own
        bowls = _bowls(state)
        if not bowls:
            return True
        # the nearest bowl; a bowl hardly farther (within 2 cm) counts as nearest too
        near = min(_dist(state, b, w) for w in bowls)
        return any(
            self._right_of(state, rel, b, w, tol) for w in bowls if _dist(state, b, w) <= near + self.TIE
        )

    def satisfied(self, state):
        rel = relations(state)
        return all(self._ok(state, rel, b) for b in _blocks(state))

    def score(self, state):
        bl = _blocks(state)
        if not bl:
            return 1.0
        rel = relations(state)
        return sum(self._ok(state, rel, b) for b in bl) / len(bl)

    def feasible(self, scene):
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _world_sample_scene(rng)

    def plan(self, state):
        if self.satisfied(state):
            return []
        if not _bowls(state):
            return None
        # nearest bowl of each unmatched block, decided where it stands now
        dest = {b: self._nearest_bowl(state, b) for b in _blocks(state) if f"{_color(b)} bowl" not in state.positions}

        def bad(s, rel, b):
            if b in dest:
                return not self._right_of(s, rel, b, dest[b], tol=-0.004)
            return rel.in_bowl(b) != f"{_color(b)} bowl"

        def move(sim, b):
            if b not in dest:
                own = f"{_color(b)} bowl"
                if any(w == own and o != b for o, w in sim.rel.inside):
                    return False  # someone else's block is in there: it leaves first
                return sim.do(PutIn(block=b, bowl=own))
            bowls = [dest[b]] + sorted(
                (w for w in _bowls(sim.state) if w != dest[b]), key=lambda w: _dist(sim.state, b, w)
            )
            for w in bowls:  # the nearest bowl; when its right side is walled off, the next nearest
                if place_right(sim, b, w):
                    dest[b] = w
                    return True
            return False

        def place_right(sim, b, w):
            wx, wy = _xy(sim.state, w)
            pts = [(wx + self.RIGHT_X, wy + dy) for dy in (0.0, -0.05, 0.05, -0.025, 0.025)]
            pts = [p for p in pts if X0 - 0.015 <= p[0] <= X1 + 0.015 and _in_table(0.0, p[1])]

            def margin(p):  # how much farther any other bowl is: small = the block sits between bowls
                d = math.hypot(p[0] - wx, p[1] - wy)
                others = [math.hypot(p[0] - o[0], p[1] - o[1]) - d for o in map(
                    lambda o: _xy(sim.state, o), _bowls(sim.state)) if o != (wx, wy)]
                return min(others, default=1.0)

            pts = [p for _, p in sorted(
                ((margin(p) < 0.03, -margin(p) if margin(p) < 0.03 else i), p) for i, p in enumerate(pts)
            )]
            for p in pts:
                if sim.do(PutAt(block=b, position=(round(p[0], 4), round(p[1], 4)))):
                    return True
            rel = sim.rel
            for o in dest:  # stack on an unmatched block already right of the same bowl
                if o != b and dest[o] == w and _base(rel, o) == o and self._right_of(sim.state, rel, o, w, tol=-0.004):
                    if sim.do(PutOn(block=b, target=_top(rel, o))):
                        return True
            return False

        out = _solve_per_block(self, state, bad, move)
        if out is not None:
            return out
        dest = {b: self._nearest_bowl(state, b) for b in _blocks(state) if f"{_color(b)} bowl" not in state.positions}
        # a first try can fail when parked or unmoved blocks crowd a bowl's right side: clear those first
        sim = _Sim(state)
        for w in set(dest.values()):
            wx, wy = _xy(state, w)
            for _ in range(MAX_ITER):
                rel = sim.rel
                crowd = [
                    o for o in _blocks(sim.state)
                    if o not in dest and rel.above(o) is None
                    and abs(sim.state.positions[o][1] - wy) < 0.1
                    and 0 < sim.state.positions[o][0] - wx < self.RIGHT_X + 0.06
                ]
                if not crowd:
                    break
                if not move(sim, crowd[0]):
                    break
        rest = _solve_per_block(self, sim.state, bad, move)
        return None if rest is None else sim.steps + rest


# --------------------------------------------------------------------------------------------
# r212: a tower of exactly three blocks
# --------------------------------------------------------------------------------------------


class R212(Intention):
    name = "r212"
    description = "A tower of exactly three blocks. If there are fewer than three blocks, don't stack anything."

    def satisfied(self, state):
        heights = sorted((len(s) for s in _stacks(state)), reverse=True)
        if len(_blocks(state)) < 3:
            return all(h == 1 for h in heights)
        return bool(heights) and heights[0] == 3 and all(h == 1 for h in heights[1:])

    def score(self, state):
        n = len(_blocks(state))
        if n == 0:
            return 1.0
        heights = sorted((len(s) for s in _stacks(state)), reverse=True)
        if n < 3:
            return sum(h == 1 for h in heights) / len(heights)
        best = min(heights[0], 3) - max(0, heights[0] - 3)
        extra = sum(h - 1 for h in heights[1:])
        return max(0.0, (best - extra) / 3)

    def feasible(self, scene):
        return len(scene.blocks) >= 3

    def sample_scene(self, rng):
        nb = int(rng.integers(3, 5))
        nw = int(rng.integers(0, 5 - nb + 1))
        return _world_sample_scene(rng, n_blocks=nb, n_bowls=nw)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        n = len(_blocks(state))
        if n < 3:
            for _ in range(MAX_ITER):
                rel = sim.rel
                stacked = [b for b in _blocks(sim.state) if rel.below(b) is not None and rel.above(b) is None]
                if not stacked:
                    break
                if not _park(sim, stacked[0]):
                    return None
            return _finish(self, sim)
        rel = sim.rel

        def tower_key(s):  # the tallest stack, preferably standing on the table
            return (-min(len(s), 3), rel.in_bowl(s[0]) is not None, -len(s))

        keep = sorted(_stacks(sim.state), key=tower_key)[0]
        for blk in reversed(keep[3:]):  # too tall: take the extra tops off
            if not _park(sim, blk, accept=lambda x, y: True):
                return None
        keep = keep[:3]
        # flatten every other stack
        for _ in range(MAX_ITER):
            rel = sim.rel
            extra = [
                b for b in _blocks(sim.state)
                if b not in keep and rel.below(b) is not None and rel.above(b) is None
            ]
            if not extra:
                break
            if not _park(sim, extra[0]):
                return None
        while len(keep) < 3:
            rel = sim.rel
            singles = [
                b for b in _blocks(sim.state)
                if b not in keep and rel.below(b) is None and rel.above(b) is None
            ]
            if not singles:
                return None
            singles.sort(key=lambda b: (rel.in_bowl(b) is not None, _dist(sim.state, b, keep[-1])))
            moved = next((b for b in singles if sim.do(PutOn(block=b, target=keep[-1]))), None)
            if moved is None:
                return None
            keep.append(moved)
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# r302: heavier-looking (darker) colours underneath
# --------------------------------------------------------------------------------------------


def _lightness(color: str) -> float:
    """CIELAB L* of the palette colour: low = dark = heavier-looking."""

    def lin(c):
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = COLORS[color]
    y = 0.2126 * lin(r) + 0.7152 * lin(g) + 0.0722 * lin(b)
    return 116 * y ** (1 / 3) - 16 if y > 0.008856 else 903.3 * y


LIGHTNESS = {c: _lightness(c) for c in COLOR_NAMES}
SAME_WEIGHT = 2.5  # L* differences below this look equally heavy (either order is fine)


class R302(Intention):
    name = "r302"
    description = (
        "Stack blocks only on blocks of a lighter colour... no, the other way round. Heavier-looking colours "
        "underneath. Sensible, like big books on the bottom shelf."
    )

    @staticmethod
    def _pair_ok(upper: str, lower: str) -> bool:
        return LIGHTNESS[_color(lower)] <= LIGHTNESS[_color(upper)] + SAME_WEIGHT

    def satisfied(self, state):
        rel = relations(state)
        if len(_blocks(state)) < 2:
            return True
        return bool(rel.on) and all(self._pair_ok(a, b) for a, b in rel.on)

    def score(self, state):
        n = len(_blocks(state))
        if n < 2:
            return 1.0
        rel = relations(state)
        good = sum(self._pair_ok(a, b) for a, b in rel.on)
        bad = len(rel.on) - good
        return good / (n - 1 + bad)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _world_sample_scene(rng)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        # take every stack apart (tops first), then build one tower, darkest at the bottom
        for _ in range(MAX_ITER):
            rel = sim.rel
            stacked = [b for b in _blocks(sim.state) if rel.below(b) is not None and rel.above(b) is None]
            if not stacked:
                break
            if not _park(sim, stacked[0]):
                return None
        order = sorted(_blocks(sim.state), key=lambda b: (LIGHTNESS[_color(b)], b))
        for upper, lower in zip(order[1:], order[:-1]):
            if not sim.do(PutOn(block=upper, target=lower)):
                return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# r342: pull blocks near the edge back to the middle
# --------------------------------------------------------------------------------------------


class R342(Intention):
    name = "r342"
    description = "Whatever's closest to the edge, pull it back to the middle. Don't want anything falling off."

    SAFE = 0.08  # block centres at least this far from every table edge

    def _ok(self, state, b, slack=0.0):
        x, y = _xy(state, b)
        return _edge_distance(x, y) >= self.SAFE + slack

    def satisfied(self, state):
        return all(self._ok(state, b) for b in _blocks(state))

    def score(self, state):
        bl = _blocks(state)
        return 1.0 if not bl else sum(self._ok(state, b) for b in bl) / len(bl)

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _world_sample_scene(rng)

    def plan(self, state):
        blocks = _blocks(state)
        if not blocks:
            return []
        # the block nearest an edge is pulled back to the middle even when it is not at risk
        rel0 = relations(state)
        closest = min(
            (b for b in blocks if rel0.above(b) is None and rel0.in_bowl(b) is None),
            key=lambda b: _edge_distance(*_xy(state, b)),
            default=None,
        )
        if closest is not None and _edge_distance(*_xy(state, closest)) >= 0.15:
            closest = None  # already in the middle part of the table

        def bad(s, rel, b):
            if b == closest and _edge_distance(*_xy(s, b)) < 0.15:
                return True
            return not self._ok(s, b, slack=0.02 if rel.in_bowl(b) is None else 0.005)

        def move(sim, b):
            if _move_to_spot(
                sim, b, accept=lambda x, y: _edge_distance(x, y) >= 0.15,
                key=lambda x, y: math.hypot(x, y + 0.5),
            ):
                return True
            rel = sim.rel
            for o in sorted(_blocks(sim.state), key=lambda o: math.hypot(*np.subtract(_xy(sim.state, o), (0, -0.5)))):
                if o != b and _base(rel, o) != b and _edge_distance(*_xy(sim.state, o)) >= 0.12:
                    if sim.do(PutOn(block=b, target=_top(rel, o))):
                        return True
            return False

        return _solve_per_block(self, state, bad, move, park_key=lambda x, y: _edge_distance(x, y) >= 0.12)


ALL = [R018, R062, R086, R114, R171, R235, R256, R323, R033, R129, R212, R302, R342]
