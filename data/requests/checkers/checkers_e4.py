"""Checkers for the pass-3 translation check, writer e4: request text and the world's public API only."""

from __future__ import annotations

import itertools

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BOWL_RADIUS,
    COLORS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    WorldState,
    apply_skill,
    relations,
    sample_scene,
    table_position_name,
)

# --------------------------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------------------------

CORNERS = {"top left corner", "top right corner", "bottom left corner", "bottom right corner"}


def _color(name: str) -> str:
    return name.split(" ", 1)[0]


def _names(x) -> list[str]:
    return list(x.objects) if isinstance(x, Scene) else list(x.positions)


def _blocks(x) -> list[str]:
    return [n for n in _names(x) if n.endswith(" block")]


def _bowls(x) -> list[str]:
    return [n for n in _names(x) if n.endswith(" bowl")]


def _match(x, block: str) -> str | None:
    bowl = f"{_color(block)} bowl"
    return bowl if bowl in _names(x) else None


def _xy(state: WorldState, name: str) -> np.ndarray:
    return np.asarray(state.positions[name][:2], dtype=float)


def _dist(a, b) -> float:
    return float(np.hypot(a[0] - b[0], a[1] - b[1]))


def _rightmost_bowl(state: WorldState) -> str | None:
    bowls = state.bowls
    return max(bowls, key=lambda w: state.positions[w][0]) if bowls else None


def _leftmost_bowl(state: WorldState) -> str | None:
    bowls = state.bowls
    return min(bowls, key=lambda w: state.positions[w][0]) if bowls else None


def _stacks(state: WorldState) -> list[list[str]]:
    """Every pile of blocks, bottom first (a lone block is a pile of one)."""
    rel = relations(state)
    out = []
    for b in state.blocks:
        if rel.below(b) is None:
            pile = [b]
            while (a := rel.above(pile[-1])) is not None and a not in pile:
                pile.append(a)
            out.append(pile)
    return out


def _flat(state: WorldState, b: str) -> bool:
    """On the table (not in a bowl, not on a block)."""
    return b in relations(state).on_table


def _side_ok(state: WorldState, block: str, obj: str, side: str) -> bool:
    """``block`` stands on the table next to ``obj`` on the given side (within 45 degrees)."""
    rel = relations(state)
    if block not in rel.on_table or not rel.is_next_to(block, obj):
        return False
    dx, dy = _xy(state, block) - _xy(state, obj)
    if side == "right":
        return dx > 0 and abs(dy) <= dx
    if side == "left":
        return dx < 0 and abs(dy) <= -dx
    if side == "front":
        return dy < 0 and abs(dx) <= -dy
    if side == "behind":
        return dy > 0 and abs(dx) <= dy
    return True


_XS = np.round(np.arange(-0.28, 0.2801, 0.02), 3)
_YS = np.round(np.arange(-0.78, -0.2199, 0.02), 3)
GRID = [(float(x), float(y)) for x in _XS for y in _YS]


def _ring(center, pref_deg: float = 0.0, half_width: float = 180.0, radii=(0.097, 0.105, 0.115, 0.125)):
    """Points around ``center`` (angle 0 = right, 90 = behind), nearest the preferred angle first."""
    pts = []
    for da in np.arange(0.0, half_width + 1e-9, 7.5):
        for sgn in ((1,) if da == 0 else (1, -1)):
            a = np.deg2rad(pref_deg + sgn * da)
            for r in radii:
                pts.append((float(center[0] + r * np.cos(a)), float(center[1] + r * np.sin(a))))
    return pts


class _Sim:
    """A plan under construction, executed symbolically as it grows."""

    def __init__(self, state: WorldState):
        self.state = state
        self.steps: list = []

    def copy(self) -> _Sim:
        s = _Sim(self.state)
        s.steps = list(self.steps)
        return s

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


def _place(sim: _Sim, block: str, skills=(), points=(), check=None) -> bool:
    """First of ``skills`` then PutAt ``points`` that succeeds (and passes ``check``)."""
    for sk in list(skills) + [PutAt(block=block, position=p) for p in points]:
        new, fail = apply_skill(sim.state, sk)
        if fail is None and (check is None or check(new)):
            sim.state = new
            sim.steps.append(sk)
            return True
    return False


def _top_of(state: WorldState, block: str) -> str:
    rel = relations(state)
    t = block
    while (a := rel.above(t)) is not None:
        t = a
    return t


def _clear_above(sim: _Sim, block: str, ok=None) -> bool:
    while sim.rel.above(block) is not None:
        if not _park(sim, _top_of(sim.state, sim.rel.above(block)), ok):
            return False
    return True


def _park(sim: _Sim, block: str, ok=None, pref=None, points=None) -> bool:
    """Set ``block`` flat on the table at a free point (``ok(xy)``), nearest ``pref``."""
    if not _clear_above(sim, block, ok):
        return False
    p0 = _xy(sim.state, block) if pref is None else pref
    pts = [p for p in (GRID if points is None else points) if ok is None or ok(p)]
    pts.sort(key=lambda p: _dist(p, p0))
    return _place(sim, block, (), pts)


def _flatten(sim: _Sim, ok=None, only=None) -> bool:
    """Take every block that sits on another block down onto the table."""
    for _ in range(40):
        rel = sim.rel
        uppers = [a for a, _ in rel.on if rel.above(a) is None and (only is None or a in only)]
        if not uppers:
            return True
        if not _park(sim, uppers[0], ok):
            return False
    return False


def _build_tower(sim: _Sim, order: list[str], base_ok, base_points, pref=None) -> bool:
    """Pile ``order`` (bottom first) with the bottom where ``base_ok(state)`` holds."""
    base = order[0]
    if not (_flat(sim.state, base) and base_ok(sim.state)):
        if not _clear_above(sim, base):
            return False
        pts = list(base_points)
        if pref is not None:
            pts.sort(key=lambda p: _dist(p, pref))
        if not _place(sim, base, (), pts, check=base_ok):
            return False
    for lower, upper in zip(order, order[1:]):
        if sim.rel.below(upper) == lower:
            continue
        if not _clear_above(sim, upper) or not _clear_above(sim, lower):
            return False
        if not sim.do(PutOn(block=upper, target=lower)):
            return False
    return True


def _one_tower(state: WorldState, blocks: list[str]) -> list[str] | None:
    """The pile (bottom first) if ``blocks`` are exactly one pile standing on the table."""
    if not blocks:
        return None
    piles = [p for p in _stacks(state) if set(p) & set(blocks)]
    if len(piles) != 1 or set(piles[0]) != set(blocks):
        return None
    if not _flat(state, piles[0][0]):
        return None
    return piles[0]


def _tower_score(state: WorldState, blocks: list[str]) -> float:
    if not blocks:
        return 1.0
    piles = _stacks(state)
    best = max((len(set(p) & set(blocks)) for p in piles), default=0)
    return best / len(blocks)


def _force(scene: Scene, rng: np.random.Generator, blocks=(), bowls=()) -> Scene:
    """Change colours of sampled objects so that the required block/bowl colours appear."""
    bl = [_color(b) for b in scene.blocks]
    bw = [_color(w) for w in scene.bowls]
    for want, lst in ((blocks, bl), (bowls, bw)):
        for c in want:
            if c in lst:
                continue
            idx = [i for i, x in enumerate(lst) if x not in want]
            if idx:
                lst[int(rng.choice(idx))] = c
            else:
                lst.append(c)
    return Scene(objects=[f"{c} block" for c in bl] + [f"{c} bowl" for c in bw])


def _sample(rng, feasible, n_blocks=(2, 3), n_bowls=(1, 2), matching=None, blocks=(), bowls=()) -> Scene:
    for _ in range(2000):
        sc = sample_scene(rng, n_blocks=n_blocks, n_bowls=n_bowls, matching=matching)
        sc = _force(sc, rng, blocks, bowls)
        if 3 <= len(sc.objects) <= 5 and feasible(sc):
            return sc
    raise RuntimeError("no feasible scene found")


def _finish(self, sim: _Sim):
    return sim.steps if self.satisfied(sim.state) else None


# --------------------------------------------------------------------------------------------
# "beside the matching bowl" family: r065, r306, r349
# --------------------------------------------------------------------------------------------


class _BesideMatch(Intention):
    side = "right"
    unmatched_out_of_bowls = False

    def _ok(self, state, b) -> bool:
        bowl = _match(state, b)
        if bowl is None:
            return not self.unmatched_out_of_bowls or relations(state).in_bowl(b) is None
        return _side_ok(state, b, bowl, self.side)

    def satisfied(self, state):
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state):
        bs = state.blocks
        return sum(self._ok(state, b) for b in bs) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return any(_match(scene, b) for b in scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, matching=True)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for b in state.blocks:
            if _match(state, b) is None and not self._ok(sim.state, b):
                if not _park(sim, b):
                    return None
        pref = {"right": 0.0, "behind": 90.0, "left": 180.0, "front": -90.0, "nearest": 0.0}[self.side]
        width = 180.0 if self.side == "nearest" else 40.0
        for b in state.blocks:
            bowl = _match(state, b)
            if bowl is None or self._ok(sim.state, b):
                continue
            if not _clear_above(sim, b):
                return None
            skills = [PutNextTo(block=b, target=bowl, side=self.side)]
            pts = _ring(_xy(sim.state, bowl), pref, width)
            if self.side == "nearest":
                here = _xy(sim.state, b)
                pts.sort(key=lambda p: _dist(p, here))
            if not _place(sim, b, skills, pts, check=lambda s, b=b: self._ok(s, b)):
                return None
        return _finish(self, sim)


class R065(_BesideMatch):
    """Reading: each block with a same-colour bowl stands on the table touching-close to that bowl on
    its right-hand side (within 45 degrees of straight right), never inside any bowl; blocks without
    a matching bowl may be anywhere except inside a bowl."""

    name = "r065"
    description = "Blocks go next to the bowl of their colour, on the right, like a label on a shelf. Not inside."
    side = "right"
    unmatched_out_of_bowls = True


class R306(_BesideMatch):
    """Reading: each block with a same-colour bowl stands on the table next to that bowl on its right
    (within 45 degrees of straight right); blocks with no matching bowl are left free."""

    name = "r306"
    description = "Place each block to the right of the bowl that matches it. Bowls are the call numbers, blocks are the books."
    side = "right"


class R349(_BesideMatch):
    """Reading: each block with a same-colour bowl stands flat on the table next to that bowl (any
    side), not in it; blocks with no matching bowl are left free."""

    name = "r349"
    description = "Could you put the blocks beside the bowls that match them? Not in, just beside, so I can see them."
    side = "nearest"


# --------------------------------------------------------------------------------------------
# rows
# --------------------------------------------------------------------------------------------


def _build_row(state: WorldState, order: list[str], y_rows, check, band=0.045, pitch=0.05):
    """Put ``order`` left to right in a row at one of ``y_rows``; first that passes ``check``."""
    for y in y_rows:
        sim = _Sim(state)
        ok_out = lambda p, y=y: abs(p[1] - y) >= band + 0.005  # noqa: E731
        good = True
        # clear the band of loose blocks standing on the table (or piled there)
        for b in list(state.blocks):
            rel = sim.rel
            if rel.in_bowl(b) is None and abs(sim.state.positions[b][1] - y) < band and b not in order:
                if not _park(sim, b, ok_out):
                    good = False
                    break
        if not good:
            continue
        for b in order:
            rel = sim.rel
            if abs(sim.state.positions[b][1] - y) < band and (rel.in_bowl(b) is None):
                if not _park(sim, b, ok_out):
                    good = False
                    break
        if not good:
            continue
        x = -0.27
        for b in order:
            if not _clear_above(sim, b, ok_out):
                good = False
                break
            placed = False
            while x <= 0.285:
                if sim.do(PutAt(block=b, position=(round(x, 3), y))):
                    placed = True
                    x += pitch
                    break
                x += 0.01
            if not placed:
                good = False
                break
        if good and check(sim.state):
            return sim.steps
    return None


RAINBOW = ["red", "orange", "yellow", "green", "blue", "purple"]


class R002(Intention):
    """Reading: every block flat on the table within 15 cm of the front (bottom, low-y) edge, in one
    line (y spread <= 6 cm), ordered left to right red, orange, yellow, green, blue, purple, with
    non-rainbow colours (pink, cyan, brown, gray) to the right of all rainbow ones in any order."""

    name = "r002"
    description = (
        "Line the blocks up along the front edge in rainbow order, red first, then orange, yellow, green, "
        "blue, purple. Any colours that aren't in the rainbow go at the end."
    )

    @staticmethod
    def _key(b):
        c = _color(b)
        return RAINBOW.index(c) if c in RAINBOW else len(RAINBOW)

    def _order_ok(self, state):
        bs = sorted(state.blocks, key=lambda b: state.positions[b][0])
        keys = [self._key(b) for b in bs]
        xs = [state.positions[b][0] for b in bs]
        return all(k1 <= k2 for k1, k2 in zip(keys, keys[1:])) and all(x2 - x1 >= 0.03 for x1, x2 in zip(xs, xs[1:]))

    def _in_strip(self, state, b):
        return _flat(state, b) and state.positions[b][1] < -0.65

    def satisfied(self, state):
        bs = state.blocks
        if not all(self._in_strip(state, b) for b in bs):
            return False
        ys = [state.positions[b][1] for b in bs]
        return max(ys) - min(ys) <= 0.06 and self._order_ok(state)

    def score(self, state):
        bs = state.blocks
        if not bs:
            return 1.0
        if self.satisfied(state):
            return 1.0
        frac = sum(self._in_strip(state, b) for b in bs) / len(bs)
        return 0.5 * frac + 0.4 * float(self._order_ok(state))

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and any(_color(b) in RAINBOW for b in scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def plan(self, state):
        if self.satisfied(state):
            return []
        order = sorted(state.blocks, key=lambda b: (self._key(b), b))
        return _build_row(state, order, [-0.77, -0.75, -0.73, -0.71, -0.69], self.satisfied)


LISTED = ["purple", "gray", "green", "blue", "red", "yellow"]


class R257(Intention):
    """Reading: the purple, gray, green, blue, red and yellow blocks that are present stand flat on
    the table ordered left to right in that sequence (x increasing by >= 2 cm); other blocks free."""

    name = "r257"
    description = (
        "Purple, gray, green, blue, red, yellow, left to right. That's the tube draw order at work and it's "
        "burned into my brain. Skip whatever's missing."
    )

    def _listed(self, x):
        return sorted([b for b in _blocks(x) if _color(b) in LISTED], key=lambda b: LISTED.index(_color(b)))

    def satisfied(self, state):
        bs = self._listed(state)
        if not all(_flat(state, b) for b in bs):
            return False
        xs = [state.positions[b][0] for b in bs]
        return all(x2 - x1 >= 0.02 for x1, x2 in zip(xs, xs[1:]))

    def score(self, state):
        bs = self._listed(state)
        if len(bs) < 2:
            return 1.0
        flat = sum(_flat(state, b) for b in bs) / len(bs)
        xs = [state.positions[b][0] for b in bs]
        pairs = list(itertools.combinations(range(len(bs)), 2))
        ordered = sum(xs[j] - xs[i] >= 0.02 for i, j in pairs) / len(pairs)
        return 0.5 * flat + 0.5 * ordered

    def feasible(self, scene):
        return len(self._listed(scene)) >= 2

    def sample_scene(self, rng):
        return _sample(rng, lambda sc: len(self._listed(sc)) >= 3, n_blocks=3, n_bowls=(1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        bs = self._listed(state)
        return _build_row(state, bs, [-0.5, -0.42, -0.58, -0.34, -0.66, -0.26, -0.74], self.satisfied)


# --------------------------------------------------------------------------------------------
# no stacking: r119, r179, r226
# --------------------------------------------------------------------------------------------


class _NoStack(Intention):
    def satisfied(self, state):
        rel = relations(state)
        if rel.on:
            return False
        return all(rel.in_bowl(b) is not None or b in rel.on_table for b in state.blocks)

    def score(self, state):
        bs = state.blocks
        if not bs:
            return 1.0
        rel = relations(state)
        good = [b for b in bs if rel.below(b) is None and (rel.in_bowl(b) is not None or b in rel.on_table)]
        return len(good) / len(bs)

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        return _finish(self, sim)


class R119(_NoStack):
    """Reading: no block rests on another block (two blocks in one bowl count as a stack); every
    block is either in a bowl or flat on the table."""

    name = "r119"
    description = (
        "Don't stack anything, ever. Stacks fall over and I'm always in a rush. Blocks go in bowls or flat on the table."
    )


class R226(_NoStack):
    """Reading: no block rests on top of another block (also not two in one bowl); blocks in bowls
    or flat on the table are fine."""

    name = "r226"
    description = (
        "Nothing on top of anything else, please. My hands aren't what they were and I'd only knock a tower over."
    )


class R179(_NoStack):
    """Reading: final table has no block on another block (two in one bowl also count); each block is
    flat on the table or in a bowl. The plan sets each taken-down block beside the one it sat on."""

    name = "r179"
    description = (
        "Any block sitting on top of another block should be taken down and put next to it. I want everything "
        "flat on the table or in a bowl."
    )

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(40):
            rel = sim.rel
            uppers = [(a, b) for a, b in rel.on if rel.above(a) is None]
            if not uppers:
                break
            a, b = uppers[0]
            if not _place(sim, a, [PutNextTo(block=a, target=b, side="nearest")]):
                base = _xy(sim.state, b)
                if not _park(sim, a, pref=base):
                    return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# bowls by colour: r019, r292, r139, r209, r144
# --------------------------------------------------------------------------------------------


class R019(Intention):
    """Reading: every block whose colour has a bowl is in that bowl; blocks with no same-colour bowl
    must not sit in a bowl of another colour (anywhere else is fine)."""

    name = "r019"
    description = "Blocks go into bowls of their own colour. That's the only sensible way to keep accounts."

    def _ok_unmatched(self, state, b):
        return relations(state).in_bowl(b) is None

    def _ok(self, state, b):
        bowl = _match(state, b)
        if bowl is None:
            return self._ok_unmatched(state, b)
        return relations(state).in_bowl(b) == bowl

    def satisfied(self, state):
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state):
        bs = state.blocks
        return sum(self._ok(state, b) for b in bs) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return any(_match(scene, b) for b in scene.blocks)

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, matching=True)

    def _park_unmatched(self, sim, b):
        return _park(sim, b)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(30):
            rel = sim.rel
            bad = [b for b in state.blocks if not self._ok(sim.state, b)]
            if not bad:
                break
            # first empty wrong bowls (top first), then the loose unmatched, then the matched
            inb = [b for b in bad if rel.in_bowl(b) is not None]
            bad = inb or sorted(bad, key=lambda b: _match(state, b) is not None)
            free = [b for b in bad if rel.above(b) is None]
            if not free:
                if not _park(sim, _top_of(sim.state, bad[0])):
                    return None
                continue
            b = free[0]
            if not _clear_above(sim, b):
                return None
            bowl = _match(state, b)
            if bowl is None:
                if not self._park_unmatched(sim, b):
                    return None
            elif not sim.do(PutIn(block=b, bowl=bowl)):
                return None
        return _finish(self, sim)


class R292(R019):
    """Reading: every block with a same-colour bowl is in it; every block without one stays out of
    the bowls, on the right third of the table (x > 0.1 m), like a returns cart."""

    name = "r292"
    description = (
        "Each block goes in the bowl of its own colour. If a block has no matching bowl, keep it to one side on "
        "the right, like a returns cart."
    )

    def _ok_unmatched(self, state, b):
        return relations(state).in_bowl(b) is None and state.positions[b][0] > 0.1

    def _park_unmatched(self, sim, b):
        y = sim.state.positions[b][1]
        return _park(sim, b, ok=lambda p: p[0] >= 0.13, pref=(0.22, min(-0.24, max(-0.76, y))))


class R139(Intention):
    """Reading: every block ends in a bowl; a block whose colour has a bowl is in that bowl; the
    others are spread so no other-coloured block could move to a bowl with two fewer blocks."""

    name = "r139"
    description = (
        "Sort the blocks by bowl: a block goes in the bowl of its colour, otherwise into the bowl with the fewest "
        "blocks so far. Keep it balanced."
    )

    @staticmethod
    def _counts(state):
        rel = relations(state)
        c = {w: 0 for w in state.bowls}
        for b in state.blocks:
            if (w := rel.in_bowl(b)) is not None:
                c[w] += 1
        return c

    def _bad(self, state):
        rel = relations(state)
        counts = self._counts(state)
        lo = min(counts.values()) if counts else 0
        bad = []
        for b in state.blocks:
            w = rel.in_bowl(b)
            m = _match(state, b)
            if w is None or (m is not None and w != m) or (m is None and counts[w] - lo >= 2):
                bad.append(b)
        return bad

    def satisfied(self, state):
        return bool(state.bowls) and not self._bad(state)

    def score(self, state):
        bs = state.blocks
        return 1.0 - len(self._bad(state)) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=2)

    def plan(self, state):
        if self.satisfied(state):
            return []
        rel = relations(state)
        bowls = state.bowls
        target: dict[str, str] = {}
        counts = {w: 0 for w in bowls}
        for b in state.blocks:
            if (m := _match(state, b)) is not None:
                target[b] = m
                counts[m] += 1
        for b in sorted(b for b in state.blocks if b not in target):
            lo = min(counts.values())
            cands = [w for w in bowls if counts[w] == lo]
            here = rel.in_bowl(b)
            w = here if here in cands else min(cands, key=lambda w: _dist(_xy(state, w), _xy(state, b)))
            target[b] = w
            counts[w] += 1
        sim = _Sim(state)
        for _ in range(3):
            for b in state.blocks:
                if sim.rel.in_bowl(b) == target[b]:
                    continue
                if not _clear_above(sim, b) or not sim.do(PutIn(block=b, bowl=target[b])):
                    return None
            if all(sim.rel.in_bowl(b) == target[b] for b in state.blocks):
                break
        return _finish(self, sim)


class R209(Intention):
    """Reading: with a gray bowl, the gray block is in it; without one, the gray block stands flat on
    the table next to the leftmost bowl (any side). Other blocks are free."""

    name = "r209"
    description = (
        "Gray block goes in the gray bowl. No gray bowl? Next to the leftmost bowl. Gray is for stuff I haven't "
        "triaged yet."
    )
    G = "gray block"

    def satisfied(self, state):
        if self.G not in state.positions:
            return True
        if "gray bowl" in state.positions:
            return relations(state).in_bowl(self.G) == "gray bowl"
        lb = _leftmost_bowl(state)
        return lb is not None and _side_ok(state, self.G, lb, "any")

    def score(self, state):
        return float(self.satisfied(state))

    def feasible(self, scene):
        return self.G in scene.objects and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        bowls = ("gray",) if rng.random() < 0.5 else ()
        return _sample(rng, self.feasible, blocks=("gray",), bowls=bowls)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _clear_above(sim, self.G):
            return None
        if "gray bowl" in state.positions:
            if not sim.do(PutIn(block=self.G, bowl="gray bowl")):
                return None
        else:
            lb = _leftmost_bowl(state)
            here = _xy(state, self.G)
            pts = sorted(_ring(_xy(state, lb)), key=lambda p: _dist(p, here))
            if not _place(sim, self.G, [PutNextTo(block=self.G, target=lb, side="nearest")], pts,
                          check=lambda s: _side_ok(s, self.G, lb, "any")):
                return None
        return _finish(self, sim)


class R144(Intention):
    """Reading: the left half (x < 0) is untouched; every block on the right half (x >= 0) ends in a
    bowl (a right-half bowl, own colour first, when there is one). Judged on the final table: no
    block may be left loose at x >= 0."""

    name = "r144"
    description = (
        "Leave the left half of the table exactly as it is and tidy everything on the right half into the bowls."
    )

    def _bad(self, state):
        rel = relations(state)
        return [b for b in state.blocks if state.positions[b][0] >= 0 and rel.in_bowl(b) is None]

    def satisfied(self, state):
        return not self._bad(state)

    def score(self, state):
        bs = state.blocks
        return 1.0 - len(self._bad(state)) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def _bowl_for(self, state, b):
        right = [w for w in state.bowls if state.positions[w][0] >= 0]
        m = _match(state, b)
        if m in right:
            return m
        pool = right or ([m] if m else state.bowls)
        return min(pool, key=lambda w: _dist(_xy(state, w), _xy(state, b)))

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(20):
            bad = self._bad(sim.state)
            if not bad:
                break
            b = bad[0]
            if not _clear_above(sim, b, ok=lambda p: p[0] >= 0.02):
                return None
            if not sim.do(PutIn(block=b, bowl=self._bowl_for(sim.state, b))):
                return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# regions: r357, r350, r089
# --------------------------------------------------------------------------------------------


def _not_corner(p, margin=0.025):
    return all(
        table_position_name((p[0] + dx, p[1] + dy)) not in CORNERS
        for dx in (-margin, 0, margin)
        for dy in (-margin, 0, margin)
    )


class R357(Intention):
    """Reading: no block (loose, piled or in a bowl) lies in one of the four corner cells of the
    table's 3x3 grid (top/bottom left/right corners)."""

    name = "r357"
    description = "No block in the corners, please. I lose things in the corners."

    def _ok(self, state, b):
        return table_position_name(state.positions[b][:2]) not in CORNERS

    def satisfied(self, state):
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state):
        bs = state.blocks
        return sum(self._ok(state, b) for b in bs) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(20):
            bad = [b for b in state.blocks if not self._ok(sim.state, b)]
            if not bad:
                break
            if not _park(sim, bad[0], ok=_not_corner):
                return None
        return _finish(self, sim)


class R350(Intention):
    """Reading: the left third of the table (x < -0.1 m, the grid's left column) holds no block at
    all; blocks elsewhere are fine."""

    name = "r350"
    description = "Keep the left side free, that's my good side, I rest my arm there."

    def _ok(self, state, b):
        return state.positions[b][0] > -0.1

    def satisfied(self, state):
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state):
        bs = state.blocks
        return sum(self._ok(state, b) for b in bs) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for _ in range(20):
            bad = [b for b in state.blocks if not self._ok(sim.state, b)]
            if not bad:
                break
            if not _park(sim, bad[0], ok=lambda p: p[0] >= -0.06):
                return None
        return _finish(self, sim)


class R089(Intention):
    """Reading: no block in any bowl; every block stands on the table left of all bowls (centre
    further left than the leftmost bowl's left rim)."""

    name = "r089"
    description = (
        "Nothing in the bowls, they're my reference colours, I like to look at them empty. Blocks go to the left "
        "of the bowls."
    )

    def _ok(self, state, b):
        if not state.bowls:
            return relations(state).in_bowl(b) is None
        lb = min(state.positions[w][0] for w in state.bowls)
        return relations(state).in_bowl(b) is None and state.positions[b][0] < lb - BOWL_RADIUS

    def satisfied(self, state):
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state):
        bs = state.blocks
        return sum(self._ok(state, b) for b in bs) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def plan(self, state):
        if self.satisfied(state):
            return []
        lb = min(state.positions[w][0] for w in state.bowls)
        xs = np.round(np.arange(-0.318, lb - 0.0699, 0.01), 3)
        ys = np.round(np.arange(-0.80, -0.1999, 0.02), 3)
        pts = [(float(x), float(y)) for x in xs for y in ys]
        sim = _Sim(state)
        ok = lambda p: p[0] <= lb - 0.07  # noqa: E731
        for _ in range(20):
            bad = [b for b in state.blocks if not self._ok(sim.state, b)]
            if not bad:
                break
            b = bad[0]
            if not _park(sim, b, ok=ok, pref=(lb - 0.097, sim.state.positions[b][1]), points=pts):
                return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# single-block relations: r028, r203
# --------------------------------------------------------------------------------------------


class R028(Intention):
    """Reading: the yellow block rests directly on the green block; everything else is free."""

    name = "r028"
    description = (
        "Put the yellow block on top of the green one. Looks like a marrow flower, which cheers me up in winter."
    )
    Y, G = "yellow block", "green block"

    def satisfied(self, state):
        return relations(state).below(self.Y) == self.G

    def score(self, state):
        return float(self.satisfied(state))

    def feasible(self, scene):
        return self.Y in scene.objects and self.G in scene.objects

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, blocks=("yellow", "green"))

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _clear_above(sim, self.G) or not _clear_above(sim, self.Y):
            return None
        if not sim.do(PutOn(block=self.Y, target=self.G)):
            return None
        return _finish(self, sim)


class R203(Intention):
    """Reading: if pink block and pink bowl exist, the pink block stands on the table next to the
    pink bowl on its front (low-y) side; if cyan block and cyan bowl exist, the cyan block stands
    next to the cyan bowl behind it (high-y side). Missing pairs: no requirement."""

    name = "r203"
    description = (
        "Pink block in front of the pink bowl, cyan block behind the cyan bowl. That's us two. If either is "
        "missing, skip it, no fallback."
    )
    PAIRS = (("pink block", "pink bowl", "front", -90.0), ("cyan block", "cyan bowl", "behind", 90.0))

    def _pairs(self, x):
        names = _names(x)
        return [p for p in self.PAIRS if p[0] in names and p[1] in names]

    def satisfied(self, state):
        return all(_side_ok(state, b, w, s) for b, w, s, _ in self._pairs(state))

    def score(self, state):
        ps = self._pairs(state)
        return sum(_side_ok(state, b, w, s) for b, w, s, _ in ps) / len(ps) if ps else 1.0

    def feasible(self, scene):
        return bool(self._pairs(scene))

    def sample_scene(self, rng):
        k = int(rng.integers(3))
        blocks = [("pink",), ("cyan",), ("pink", "cyan")][k]
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2), blocks=blocks, bowls=blocks)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        for b, w, side, ang in self._pairs(state):
            if _side_ok(sim.state, b, w, side):
                continue
            if not _clear_above(sim, b):
                return None
            pts = _ring(_xy(state, w), ang, 40.0)
            if not _place(sim, b, [PutNextTo(block=b, target=w, side=side)], pts,
                          check=lambda s, b=b, w=w, side=side: _side_ok(s, b, w, side)):
                return None
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# towers: r054, r094, r200, r175, r210, r358, r105
# --------------------------------------------------------------------------------------------


def _region_points(x0, x1, y0, y1, step=0.01):
    xs = np.round(np.arange(x0, x1 + 1e-9, step), 3)
    ys = np.round(np.arange(y0, y1 + 1e-9, step), 3)
    return [(float(x), float(y)) for x in xs for y in ys]


class R054(Intention):
    """Reading: all blocks in one pile standing on the table, its bottom block next to the rightmost
    bowl ("the bowl on the right") and on that bowl's right-hand side (x beyond the bowl's centre)."""

    name = "r054"
    description = (
        "Stack every block on top of the one that's the same colour as the nearest bowl... ok that's too "
        "complicated. Just put them all in one stack by the bowl on the right."
    )

    def _base_ok(self, state, base):
        rb = _rightmost_bowl(state)
        return (
            rb is not None
            and _side_ok(state, base, rb, "any")
            and state.positions[base][0] > state.positions[rb][0]
        )

    def satisfied(self, state):
        pile = _one_tower(state, state.blocks)
        return pile is not None and self._base_ok(state, pile[0])

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        return 0.9 * _tower_score(state, state.blocks)

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        rb = _rightmost_bowl(state)
        c = _xy(state, rb)
        bs = sorted(state.blocks, key=lambda b: (not self._base_ok(sim.state, b), _dist(_xy(sim.state, b), c + (0.1, 0))))
        base = bs[0]
        order = [base] + bs[1:]
        ring = _ring(c, 0.0, 80.0)
        if not self._base_ok(sim.state, base):
            if not _place(sim, base, [PutNextTo(block=base, target=rb, side="right")], ring,
                          check=lambda s: self._base_ok(s, base)):
                return None
        if not _build_tower(sim, order, lambda s: self._base_ok(s, base), ring):
            return None
        return _finish(self, sim)


class R094(Intention):
    """Reading: all blocks in one pile standing on the table, its bottom block in the middle cell of
    the table's 3x3 grid."""

    name = "r094"
    description = (
        "Stack everything into one tower in the middle. One pile is easier to check at 7am than ten little things."
    )

    def satisfied(self, state):
        pile = _one_tower(state, state.blocks)
        return pile is not None and table_position_name(state.positions[pile[0]][:2]) == "middle"

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        return 0.9 * _tower_score(state, state.blocks)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(3, 4), n_bowls=1)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        mid = (0.0, -0.5)
        in_mid = lambda s, b: _flat(s, b) and table_position_name(s.positions[b][:2]) == "middle"  # noqa: E731
        bs = sorted(state.blocks, key=lambda b: (not in_mid(sim.state, b), _dist(_xy(sim.state, b), mid)))
        pts = _region_points(-0.08, 0.08, -0.58, -0.42)
        if not _build_tower(sim, bs, lambda s: in_mid(s, bs[0]), pts, pref=mid):
            return None
        return _finish(self, sim)


class R200(Intention):
    """Reading: all blocks in one pile standing on the table, ordered bottom to top alphabetically by
    colour name (e.g. blue, green, red)."""

    name = "r200"
    description = "Stack all the blocks into a single tower, sorted alphabetically by colour name, first one at the bottom."

    def satisfied(self, state):
        pile = _one_tower(state, state.blocks)
        return pile is not None and pile == sorted(state.blocks)

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        want = sorted(state.blocks)
        best = 0
        for p in _stacks(state):
            k = 0
            while k < len(p) and k < len(want) and p[k] == want[k]:
                k += 1
            best = max(best, k)
        return 0.9 * best / len(want) if want else 1.0

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(3, 4), n_bowls=1)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        order = sorted(state.blocks)
        base = order[0]
        if not _build_tower(sim, order, lambda s: _flat(s, base), GRID, pref=_xy(sim.state, base)):
            return None
        return _finish(self, sim)


SIMILAR = {
    frozenset(p)
    for p in (
        ("blue", "cyan"), ("blue", "purple"), ("cyan", "green"), ("red", "pink"),
        ("red", "orange"), ("orange", "yellow"), ("orange", "brown"), ("brown", "gray"),
    )
}


def _lab(rgb):
    c = np.array(rgb)
    c = np.where(c > 0.04045, ((c + 0.055) / 1.055) ** 2.4, c / 12.92)
    m = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
    x, y, z = m @ c / np.array([0.95047, 1.0, 1.08883])

    def f(t):
        return t ** (1 / 3) if t > 0.008856 else 7.787 * t + 16 / 116

    return np.array([116 * f(y) - 16, 500 * (f(x) - f(y)), 200 * (f(y) - f(z))])


LAB = {k: _lab(v) for k, v in COLORS.items()}


def _contrast(a: str, b: str) -> float:
    return float(np.linalg.norm(LAB[_color(a)] - LAB[_color(b)]))


def _similar(a: str, b: str) -> bool:
    return frozenset((_color(a), _color(b))) in SIMILAR


class R175(Intention):
    """Reading: all blocks in one pile standing on the table, and no two neighbouring blocks are of
    similar hue (similar pairs: blue/cyan, blue/purple, cyan/green, red/pink, red/orange,
    orange/yellow, orange/brown, brown/gray); the plan picks the order with the largest smallest
    neighbour contrast."""

    name = "r175"
    description = (
        "Stack all the blocks in one tower, biggest contrast between neighbours: never two similar colours like "
        "blue and cyan touching."
    )

    def satisfied(self, state):
        pile = _one_tower(state, state.blocks)
        return pile is not None and not any(_similar(a, b) for a, b in zip(pile, pile[1:]))

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        return 0.9 * _tower_score(state, state.blocks)

    def _best_order(self, blocks):
        best, val = None, -1.0
        for perm in itertools.permutations(sorted(blocks)):
            if any(_similar(a, b) for a, b in zip(perm, perm[1:])):
                continue
            v = min((_contrast(a, b) for a, b in zip(perm, perm[1:])), default=0.0)
            if v > val:
                best, val = list(perm), v
        return best

    def feasible(self, scene):
        return len(scene.blocks) >= 2 and self._best_order(scene.blocks) is not None

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(3, 4), n_bowls=1)

    def plan(self, state):
        if self.satisfied(state):
            return []
        order = self._best_order(state.blocks)
        if order is None:
            return None
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        base = order[0]
        if not _build_tower(sim, order, lambda s: _flat(s, base), GRID, pref=_xy(sim.state, base)):
            return None
        return _finish(self, sim)


class R210(Intention):
    """Reading: blocks whose colour has a bowl form one pile standing on the left half of the table
    (x < 0), blocks without one form another pile on the right half (x > 0); a group of one is a
    single block standing there; no block in any bowl."""

    name = "r210"
    description = (
        "Two stacks: blocks with a same-colour bowl on the table on the left, blocks without one on the right. "
        "Leave the bowls empty."
    )

    def _groups(self, x):
        bs = _blocks(x)
        m = [b for b in bs if _match(x, b)]
        return m, [b for b in bs if b not in m]

    def _group_ok(self, state, group, left):
        if not group:
            return True
        pile = _one_tower(state, group)
        if pile is None:
            return False
        x = state.positions[pile[0]][0]
        return x < 0 if left else x > 0

    def satisfied(self, state):
        rel = relations(state)
        if any(rel.in_bowl(b) for b in state.blocks):
            return False
        m, u = self._groups(state)
        return self._group_ok(state, m, True) and self._group_ok(state, u, False)

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        m, u = self._groups(state)
        rel = relations(state)
        out = sum(rel.in_bowl(b) is None for b in state.blocks) / max(1, len(state.blocks))
        return 0.3 * out + 0.3 * self._group_ok(state, m, True) + 0.3 * self._group_ok(state, u, False)

    def feasible(self, scene):
        m, u = self._groups(scene)
        return bool(m) and bool(u) and len(scene.blocks) >= 3

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=3, n_bowls=(1, 2), matching=True)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        for b in state.blocks:
            if sim.rel.in_bowl(b) is not None and not _park(sim, b):
                return None
        m, u = self._groups(state)
        for group, left in ((m, True), (u, False)):
            if self._group_ok(sim.state, group, left):
                continue
            side_ok = (lambda x: x < -0.03) if left else (lambda x: x > 0.03)
            pref = (-0.18, -0.5) if left else (0.18, -0.5)
            order = sorted(group, key=lambda b: (not (_flat(sim.state, b) and side_ok(sim.state.positions[b][0])),
                                                 _dist(_xy(sim.state, b), pref)))
            base = order[0]
            pts = [p for p in GRID if side_ok(p[0])]
            if not _build_tower(sim, order, lambda s, base=base, side_ok=side_ok: _flat(s, base) and side_ok(s.positions[base][0]),
                                pts, pref=pref):
                return None
        return _finish(self, sim)


FAMILIES = {
    "red": "reds", "pink": "reds",
    "blue": "blues", "purple": "blues", "cyan": "blues",
    "green": "greens",
    "yellow": "yellows", "orange": "yellows",
    "brown": "neutrals", "gray": "neutrals",
}


class R358(Intention):
    """Reading: piles match colour families exactly: reds = red+pink, blues = blue+purple+cyan,
    yellows = yellow+orange, neutrals = brown+gray, greens = green; each family present is one pile
    (a lone member stands alone) and no pile mixes families."""

    name = "r358"
    description = (
        "Stack them by colour family, reds with pinks, blues with purples, as I'd sort the fabric bolts."
    )

    @staticmethod
    def _fams(x):
        out: dict[str, list[str]] = {}
        for b in _blocks(x):
            out.setdefault(FAMILIES[_color(b)], []).append(b)
        return out

    def _fam_ok(self, state, members):
        piles = [p for p in _stacks(state) if set(p) & set(members)]
        return len(piles) == 1 and set(piles[0]) == set(members)

    def satisfied(self, state):
        return all(self._fam_ok(state, ms) for ms in self._fams(state).values())

    def score(self, state):
        bs = state.blocks
        if not bs:
            return 1.0
        good = sum(len(ms) for ms in self._fams(state).values() if self._fam_ok(state, ms))
        return good / len(bs)

    def feasible(self, scene):
        return any(len(ms) >= 2 for ms in self._fams(scene).values())

    def sample_scene(self, rng):
        pairs = [("red", "pink"), ("blue", "purple"), ("blue", "cyan"), ("purple", "cyan"),
                 ("yellow", "orange"), ("brown", "gray")]
        pair = pairs[int(rng.integers(len(pairs)))]
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2), blocks=pair)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        for ms in self._fams(state).values():
            if len(ms) < 2 or self._fam_ok(sim.state, ms):
                continue
            order = sorted(ms, key=lambda b: (not _flat(sim.state, b), b))
            base = order[0]
            if not _build_tower(sim, order, lambda s, base=base: _flat(s, base), GRID, pref=_xy(sim.state, base)):
                return None
        return _finish(self, sim)


class R105(Intention):
    """Reading: blocks form towers of exactly two (floor(n/2) of them, none taller); with an odd
    count one block stays single (the plan puts it in a bowl; anywhere is accepted)."""

    name = "r105"
    description = (
        "Pair them up \u2014 put each block on top of another block so there's little towers of two. If there's "
        "an odd one out, it can sit in a bowl."
    )

    def satisfied(self, state):
        piles = _stacks(state)
        n = len(state.blocks)
        if any(len(p) > 2 for p in piles):
            return False
        return sum(len(p) == 2 for p in piles) == n // 2

    def score(self, state):
        n = len(state.blocks)
        if n < 2:
            return 1.0
        paired = sum(len(p) for p in _stacks(state) if len(p) == 2)
        return min(1.0, paired / (2 * (n // 2)))

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 4), n_bowls=1)

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        rel = sim.rel
        bs = sorted(state.blocks, key=lambda b: (rel.in_bowl(b) is not None, b))
        odd = None
        if len(bs) % 2 == 1:
            # the odd one: a block already in a bowl if any, else the one nearest a bowl
            inb = [b for b in bs if rel.in_bowl(b) is not None]
            if inb:
                odd = inb[0]
            elif state.bowls:
                odd = min(bs, key=lambda b: min(_dist(_xy(state, b), _xy(state, w)) for w in state.bowls))
            else:
                odd = bs[-1]
        rest = [b for b in bs if b != odd]
        while rest:
            base = rest.pop(0)
            top = min(rest, key=lambda b: _dist(_xy(sim.state, b), _xy(sim.state, base)))
            rest.remove(top)
            if not sim.do(PutOn(block=top, target=base)):
                return None
        if odd is not None and sim.rel.in_bowl(odd) is None and state.bowls:
            w = min(state.bowls, key=lambda w: _dist(_xy(state, w), _xy(sim.state, odd)))
            sim.do(PutIn(block=odd, bowl=w))  # optional nicety; fine if it fails
        return _finish(self, sim)


# --------------------------------------------------------------------------------------------
# one block per bowl: r024, r202, r301
# --------------------------------------------------------------------------------------------


def _assign_bowls(state: WorldState, bowls: list[str]) -> dict[str, str]:
    """bowl -> block: keep the bottom block already in a bowl, else own colour, else nearest."""
    rel = relations(state)
    out: dict[str, str] = {}
    used: set[str] = set()
    for w in bowls:
        inside = [b for b in state.blocks if rel.in_bowl(b) == w and rel.below(b) is None]
        if inside:
            out[w] = inside[0]
            used.add(inside[0])
    for w in bowls:
        if w in out:
            continue
        free = [b for b in state.blocks if b not in used]
        if not free:
            break
        m = [b for b in free if _color(b) == _color(w)]
        b = m[0] if m else min(free, key=lambda b: _dist(_xy(state, b), _xy(state, w)))
        out[w] = b
        used.add(b)
    return out


class R024(Intention):
    """Reading: no bowl holds more than one block and min(#blocks, #bowls) bowls hold one; every
    block not in a bowl stands flat on the table next to the rightmost bowl."""

    name = "r024"
    description = (
        "One block per bowl, like one entry per line. Whatever's extra, set it beside the last bowl on the right."
    )

    def _extra_ok(self, state, b):
        rb = _rightmost_bowl(state)
        return rb is not None and _side_ok(state, b, rb, "any")

    def _bad(self, state):
        rel = relations(state)
        bad = []
        counts: dict[str, list[str]] = {}
        for b in state.blocks:
            if (w := rel.in_bowl(b)) is not None:
                counts.setdefault(w, []).append(b)
            elif not self._extra_ok(state, b):
                bad.append(b)
        for w, bs in counts.items():
            if len(bs) > 1:
                bad.extend(bs[1:])
        return bad

    def satisfied(self, state):
        rel = relations(state)
        filled = {rel.in_bowl(b) for b in state.blocks} - {None}
        return not self._bad(state) and len(filled) == min(len(state.blocks), len(state.bowls))

    def score(self, state):
        bs = state.blocks
        if self.satisfied(state):
            return 1.0
        return 0.9 * (1.0 - len(self._bad(state)) / len(bs)) if bs else 1.0

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=3, n_bowls=(1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        rb = _rightmost_bowl(state)
        assign = _assign_bowls(state, sorted(state.bowls, key=lambda w: state.positions[w][0]))
        assigned = set(assign.values())
        extras = [b for b in state.blocks if b not in assigned]

        def put_extra(b):
            if self._extra_ok(sim.state, b):
                return True
            if not _clear_above(sim, b):
                return False
            here = _xy(sim.state, b)
            pts = sorted(_ring(_xy(state, rb)), key=lambda p: _dist(p, here))
            return _place(sim, b, [PutNextTo(block=b, target=rb, side="nearest")], pts,
                          check=lambda s: self._extra_ok(s, b))

        # 1. take surplus blocks out of bowls (top first)
        for _ in range(20):
            rel = sim.rel
            surplus = [b for b in state.blocks
                       if rel.in_bowl(b) is not None and assign.get(rel.in_bowl(b)) != b and rel.above(b) is None]
            if not surplus:
                break
            b = surplus[0]
            if b in extras:
                if not put_extra(b):
                    return None
            elif not _park(sim, b):
                return None
        # 2. fill bowls
        for w, b in assign.items():
            if sim.rel.in_bowl(b) == w:
                continue
            if not _clear_above(sim, b) or not sim.do(PutIn(block=b, bowl=w)):
                return None
        # 3. extras beside the rightmost bowl
        for _ in range(3):
            for b in extras:
                if not put_extra(b):
                    return None
        return _finish(self, sim)


class R202(Intention):
    """Reading: bowls ordered left to right; the first min(#blocks, #bowls) each hold exactly one
    block, the rest stay empty; blocks beyond the bowl count form one pile (or a lone block) standing
    on the table in the middle cell of the 3x3 grid."""

    name = "r202"
    description = (
        "One block per bowl, filling bowls left to right. If there are more blocks than bowls, stack the extras "
        "in the middle."
    )

    def _bowls_ok(self, state):
        rel = relations(state)
        bowls = sorted(state.bowls, key=lambda w: state.positions[w][0])
        k = min(len(bowls), len(state.blocks))
        for i, w in enumerate(bowls):
            n = sum(rel.in_bowl(b) == w for b in state.blocks)
            if n != (1 if i < k else 0):
                return False
        return True

    def _extras_ok(self, state):
        rel = relations(state)
        extras = [b for b in state.blocks if rel.in_bowl(b) is None]
        if not extras:
            return True
        pile = _one_tower(state, extras)
        return pile is not None and table_position_name(state.positions[pile[0]][:2]) == "middle"

    def satisfied(self, state):
        return self._bowls_ok(state) and self._extras_ok(state)

    def score(self, state):
        if self.satisfied(state):
            return 1.0
        return 0.45 * self._bowls_ok(state) + 0.45 * self._extras_ok(state)

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, n_blocks=(2, 3), n_bowls=(1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        sim = _Sim(state)
        bowls = sorted(state.bowls, key=lambda w: state.positions[w][0])
        k = min(len(bowls), len(state.blocks))
        assign = _assign_bowls(state, bowls[:k])
        # blocks already in an unused bowl should not be "kept" there
        assigned = set(assign.values())
        extras = [b for b in state.blocks if b not in assigned]
        mid = (0.0, -0.5)
        for _ in range(20):
            rel = sim.rel
            surplus = [b for b in state.blocks
                       if rel.in_bowl(b) is not None and assign.get(rel.in_bowl(b)) != b and rel.above(b) is None]
            if not surplus:
                break
            if not _park(sim, surplus[0], ok=lambda p: table_position_name(p) != "middle"):
                return None
        for w, b in assign.items():
            if sim.rel.in_bowl(b) == w:
                continue
            if not _clear_above(sim, b, ok=lambda p: table_position_name(p) != "middle") or not sim.do(
                PutIn(block=b, bowl=w)
            ):
                return None
        if extras and not self._extras_ok(sim.state):
            if not _flatten(sim, ok=lambda p: table_position_name(p) != "middle", only=set(extras)):
                return None
            in_mid = lambda s, b: _flat(s, b) and table_position_name(s.positions[b][:2]) == "middle"  # noqa: E731
            order = sorted(extras, key=lambda b: (not in_mid(sim.state, b), _dist(_xy(sim.state, b), mid)))
            pts = _region_points(-0.08, 0.08, -0.58, -0.42)
            if not _build_tower(sim, order, lambda s: in_mid(s, order[0]), pts, pref=mid):
                return None
        return _finish(self, sim)


class R301(Intention):
    """Reading: all bowls empty; every block flat on the table with nothing on it; each bowl (as far
    as blocks go) has its own block just in front of it (low-y side, within 45 degrees); any extra
    block stands in the row in front of the bowls (below a bowl's centre, within 15 cm sideways)."""

    name = "r301"
    description = (
        "I'd like the bowls left empty, actually. Blocks in a tidy row in front of them, one block in front of each "
        "bowl if you can manage."
    )

    def _front_match(self, state):
        bowls, blocks = state.bowls, state.blocks
        k = min(len(bowls), len(blocks))
        if k == 0:
            return True
        if len(bowls) <= len(blocks):
            for perm in itertools.permutations(blocks, len(bowls)):
                if all(_side_ok(state, b, w, "front") for b, w in zip(perm, bowls)):
                    return True
            return False
        for perm in itertools.permutations(bowls, len(blocks)):
            if all(_side_ok(state, b, w, "front") for b, w in zip(blocks, perm)):
                return True
        return False

    def _in_front_zone(self, state, b):
        x, y = state.positions[b][:2]
        return any(
            y < state.positions[w][1] - 0.03 and abs(x - state.positions[w][0]) < 0.15 for w in state.bowls
        )

    def _loose_ok(self, state, b):
        rel = relations(state)
        return b in rel.on_table and rel.above(b) is None and self._in_front_zone(state, b)

    def satisfied(self, state):
        return all(self._loose_ok(state, b) for b in state.blocks) and self._front_match(state)

    def score(self, state):
        bs = state.blocks
        if self.satisfied(state):
            return 1.0
        return 0.9 * sum(self._loose_ok(state, b) for b in bs) / len(bs) if bs else 1.0

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible)

    def plan(self, state):
        if self.satisfied(state):
            return []
        bowls = sorted(state.bowls, key=lambda w: state.positions[w][0])
        blocks = state.blocks
        # assignment: minimise total distance (small sets: brute force)
        best, cost = None, None
        k = min(len(bowls), len(blocks))
        for bperm in itertools.permutations(blocks, k):
            for wperm in itertools.combinations(bowls, k):
                c = sum(_dist(_xy(state, b), _xy(state, w) + (0, -0.097)) for b, w in zip(bperm, wperm))
                if cost is None or c < cost:
                    best, cost = list(zip(bperm, wperm)), c
        sim = _Sim(state)
        if not _flatten(sim):
            return None
        fronts = []
        for b, w in best:
            fronts.append(b)
            if _side_ok(sim.state, b, w, "front"):
                continue
            pts = _ring(_xy(state, w), -90.0, 40.0)
            if not _place(sim, b, [PutNextTo(block=b, target=w, side="front")], pts,
                          check=lambda s, b=b, w=w: _side_ok(s, b, w, "front")):
                return None
        assigned = {b for b, _ in best}
        for b in blocks:
            if b in assigned or self._loose_ok(sim.state, b):
                continue
            skills = [PutNextTo(block=b, target=f, side=s) for f in fronts for s in ("right", "left")]
            pts = []
            for f in fronts:
                pts += _ring(_xy(sim.state, f), 0.0, 180.0, radii=(0.052, 0.06, 0.07))
            if not _place(sim, b, skills, pts, check=lambda s, b=b: self._loose_ok(s, b)):
                return None
            fronts.append(b)  # the row grows sideways
        return _finish(self, sim)
