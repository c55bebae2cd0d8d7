"""Second independent checkers, writer d2: request text and the world's public API only."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOWL_RADIUS,
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
    table_position_name,
)
from activeintent.world import sample_scene as world_sample_scene

# --------------------------------------------------------------------------------------------
# geometry helpers
# --------------------------------------------------------------------------------------------

HALF = BLOCK_SIZE / 2
GROUND_Z = HALF
LEVEL_TOL = 0.012
XMIN, XMAX = -0.28, 0.28  # block centres that keep the whole block on the 60 cm table
YMIN, YMAX = -0.78, -0.22
MIDDLE = (0.0, -0.5)
FRONT_OFFSET = BOWL_RADIUS + HALF + 0.012  # where PutNextTo puts a block beside a bowl


def _grid(step: float, xr=(XMIN, XMAX), yr=(YMIN, YMAX)) -> list[tuple[float, float]]:
    xs = np.round(np.arange(xr[0], xr[1] + 1e-9, step), 4)
    ys = np.round(np.arange(yr[0], yr[1] + 1e-9, step), 4)
    return [(float(x), float(y)) for x in xs for y in ys]


GRID = _grid(0.01)


def color(name: str) -> str:
    return name.split(" ", 1)[0]


def kind(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


def radius(name: str) -> float:
    return BOWL_RADIUS if kind(name) == "bowl" else HALF


def xy(state: WorldState, name: str) -> np.ndarray:
    p = state.positions[name]
    return np.array([p[0], p[1]], dtype=float)


def dist(a, b) -> float:
    return float(np.hypot(a[0] - b[0], a[1] - b[1]))


def in_bowl(state: WorldState, b: str) -> str | None:
    return relations(state).in_bowl(b)


def above(state: WorldState, b: str) -> str | None:
    return relations(state).above(b)


def below(state: WorldState, b: str) -> str | None:
    return relations(state).below(b)


def on_ground(state: WorldState, b: str) -> bool:
    """Standing directly on the table: not in a bowl, not on another block."""
    return (
        in_bowl(state, b) is None
        and below(state, b) is None
        and abs(state.positions[b][2] - GROUND_Z) < LEVEL_TOL
    )


def loose(state: WorldState, b: str) -> bool:
    """On the table, with nothing on top of it."""
    return on_ground(state, b) and above(state, b) is None


def topmost_above(state: WorldState, b: str) -> str | None:
    top, cur = None, above(state, b)
    seen = set()
    while cur is not None and cur not in seen:
        seen.add(cur)
        top, cur = cur, above(state, cur)
    return top


def bowl_blocks(state: WorldState, w: str) -> list[str]:
    return [a for a, bw in relations(state).inside if bw == w]


def clear(state: WorldState, p, moving: str, extra: float = 0.003) -> bool:
    """Would a block put at p be free (the world's own test, with a small safety margin)?"""
    if not (XMIN - 0.02 <= p[0] <= XMAX + 0.02 and YMIN - 0.02 <= p[1] <= YMAX + 0.02):
        return False
    for o, (ox, oy, oz) in state.positions.items():
        if o == moving:
            continue
        if kind(o) == "block" and oz > BLOCK_SIZE:
            continue
        if np.hypot(ox - p[0], oy - p[1]) < radius(o) + HALF + 0.004 + extra:
            return False
    return True


def static_clear(state: WorldState, p, movers, extra: float = 0.006) -> bool:
    """p is free of every object that will not move (bowls, blocks not in ``movers``)."""
    for o, (ox, oy, _) in state.positions.items():
        if o in movers:
            continue
        if np.hypot(ox - p[0], oy - p[1]) < radius(o) + HALF + 0.004 + extra:
            return False
    return True


def bowls_sorted(state: WorldState, key) -> list[str]:
    return sorted(state.bowls, key=key)


def leftmost_bowl(state: WorldState) -> str | None:
    return min(state.bowls, key=lambda w: (state.positions[w][0], w)) if state.bowls else None


def rightmost_bowl(state: WorldState) -> str | None:
    return max(state.bowls, key=lambda w: (state.positions[w][0], w)) if state.bowls else None


def tower_heights(state: WorldState) -> dict[str, int]:
    """Base block → number of blocks in the pile standing on it (including itself)."""
    out = {}
    for b in state.blocks:
        if below(state, b) is None:
            h, cur, seen = 1, above(state, b), {b}
            while cur is not None and cur not in seen:
                seen.add(cur)
                h, cur = h + 1, above(state, cur)
            out[b] = h
    return out


def in_front_of_bowl(state: WorldState, b: str, w: str, dx_tol: float = 0.03) -> bool:
    """On the table, directly in front of bowl w (towards the front edge), close to its rim."""
    if not on_ground(state, b):
        return False
    (bx, by), (wx, wy) = xy(state, b), xy(state, w)
    return abs(bx - wx) <= dx_tol and 0.07 <= wy - by <= 0.14


def right_of_bowl(state: WorldState, b: str, w: str, dy_tol: float = 0.03) -> bool:
    if not on_ground(state, b):
        return False
    (bx, by), (wx, wy) = xy(state, b), xy(state, w)
    return abs(by - wy) <= dy_tol and 0.07 <= bx - wx <= 0.14


def near_side_points(center, direction: str, across_tol: float) -> list[tuple[float, float]]:
    """Candidate points on one side of a bowl (front/right), best first."""
    cx, cy = float(center[0]), float(center[1])
    pts = []
    for d in np.arange(FRONT_OFFSET, 0.135, 0.005):
        for a in np.arange(-across_tol, across_tol + 1e-9, 0.005):
            if direction == "front":
                pts.append((cx + a, cy - d))
            else:  # right
                pts.append((cx + d, cy + a))
    main = (cx, cy - FRONT_OFFSET) if direction == "front" else (cx + FRONT_OFFSET, cy)
    pts.sort(key=lambda p: dist(p, main))
    return [(round(float(p[0]), 4), round(float(p[1]), 4)) for p in pts]


# --------------------------------------------------------------------------------------------
# planning helpers
# --------------------------------------------------------------------------------------------


class Builder:
    """Accumulates skills, executing each with the world's own predictor."""

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

    def put_at_spot(self, b: str, pred: Callable, key: Callable, points=None) -> bool:
        if above(self.state, b) is not None:
            return False
        pts = [p for p in (points if points is not None else GRID) if pred(p)]
        pts.sort(key=key)
        for p in pts:
            if clear(self.state, p, b) and self.do(PutAt(block=b, position=p)):
                return True
        return False

    def park(self, b: str, avoid: Callable | None = None) -> bool:
        """Move b to a free table spot near where it is (avoiding ``avoid(p)`` spots)."""
        here = xy(self.state, b)
        return self.put_at_spot(
            b,
            lambda p: avoid is None or not avoid(p),
            lambda p: (dist(p, here), p),
        )


def repair(
    state: WorldState,
    bad: Callable[[WorldState, str], bool],
    fix: Callable[[Builder, str], bool],
    priority: Callable[[str], float] | None = None,
    avoid: Callable | None = None,
    unblock: Callable[[Builder, list[str]], bool] | None = None,
    max_iter: int = 60,
) -> Builder | None:
    """Fix misplaced blocks one at a time (topmost first); move covering blocks out of the way."""
    B = Builder(state)
    for _ in range(max_iter):
        todo = [b for b in B.state.blocks if bad(B.state, b)]
        if not todo:
            return B
        todo.sort(key=lambda b: (priority(b) if priority else 0.0, -B.state.positions[b][2], b))
        progressed = False
        for b in todo:
            if above(B.state, b) is not None:
                continue
            if fix(B, b):
                progressed = True
                break
        if progressed:
            continue
        for b in todo:
            # uncover b (topmost first), then fix it at once, before the parked blocks go back
            n_before = len(B.steps)
            while (top := topmost_above(B.state, b)) is not None and B.park(top, avoid):
                pass
            if len(B.steps) > n_before:
                progressed = True
                if above(B.state, b) is None and bad(B.state, b):
                    fix(B, b)
                break
        if not progressed and unblock is not None:
            progressed = unblock(B, todo)
        if not progressed:
            return None
    return None


def at_point(state: WorldState, b: str, p, tol: float = 0.004) -> bool:
    return on_ground(state, b) and dist(xy(state, b), p) <= tol


def place_at_points(state: WorldState, targets: dict[str, tuple[float, float]]) -> Builder | None:
    """Put each block at its point on the table, parking blockers out of the way."""
    pts = list(targets.values())

    def avoid(p):
        return any(dist(p, q) < 0.075 for q in pts)

    def bad(s, b):
        return b in targets and not at_point(s, b, targets[b])

    def fix(B, b):
        p = targets[b]
        return clear(B.state, p, b, extra=0.0) and B.do(PutAt(block=b, position=p))

    def unblock(B, todo):
        for b in todo:
            p = targets[b]
            for o in B.state.blocks:
                if o == b or B.state.positions[o][2] > BLOCK_SIZE:
                    continue
                if dist(xy(B.state, o), p) < 2 * HALF + 0.008 and above(B.state, o) is None:
                    if B.park(o, avoid):
                        return True
        return False

    return repair(state, bad, fix, avoid=avoid, unblock=unblock)


def find_even_row(state, movers, n, ys, ds, xcs) -> list[tuple[float, float]] | None:
    for y in ys:
        for d in ds:
            for xc in xcs:
                pts = [(round(float(xc + (i - (n - 1) / 2) * d), 4), round(float(y), 4)) for i in range(n)]
                if pts[0][0] < XMIN - 1e-9 or pts[-1][0] > XMAX + 1e-9:
                    continue
                if all(static_clear(state, p, movers) for p in pts):
                    return pts
    return None


def find_greedy_row(state, movers, n, ys, spacing=0.06) -> list[tuple[float, float]] | None:
    xs = sorted(np.round(np.arange(XMIN, XMAX + 1e-9, 0.005), 4), key=lambda x: (abs(x), x))
    for y in ys:
        chosen: list[float] = []
        for x in xs:
            if static_clear(state, (x, y), movers) and all(abs(x - c) >= spacing for c in chosen):
                chosen.append(float(x))
                if len(chosen) == n:
                    return [(x, round(float(y), 4)) for x in sorted(chosen)]
    return None


def assign_left_to_right(state: WorldState, blocks: list[str], pts: list[tuple[float, float]]):
    order = sorted(blocks, key=lambda b: (state.positions[b][0], b))
    return dict(zip(order, sorted(pts)))


def sample_with(rng, ok: Callable[[Scene], bool], tries: int = 5000, **kw) -> Scene:
    for _ in range(tries):
        try:
            s = world_sample_scene(rng, **kw)
        except ValueError:  # e.g. too few objects for a scene
            continue
        if 3 <= len(s.objects) <= 5 and ok(s):
            return s
    raise RuntimeError("could not sample a feasible scene")


def has(scene_or_state, name: str) -> bool:
    objs = scene_or_state.objects if isinstance(scene_or_state, Scene) else scene_or_state.names
    return name in objs


class _Checker(Intention):
    """Shared scaffolding: score is 1 exactly when satisfied; plans are checked before use."""

    def _fraction(self, state: WorldState) -> float:
        raise NotImplementedError

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        return float(min(0.99, max(0.0, self._fraction(state))))

    def _build(self, state: WorldState) -> Builder | None:
        raise NotImplementedError

    def plan(self, state: WorldState) -> list[Skill] | None:
        if not self.feasible(state.scene):
            return None
        if self.satisfied(state):
            return []
        B = self._build(state)
        if B is None or not self.satisfied(B.state):
            return None
        return B.steps


def _frac(items: list[bool]) -> float:
    return sum(items) / len(items) if items else 0.0


# --------------------------------------------------------------------------------------------
# the checkers
# --------------------------------------------------------------------------------------------


class R158(_Checker):
    """Reading: if the orange block and blue bowl are both there, the orange block stands on the
    table directly in front of the blue bowl (front = towards the front edge, within 4 cm of its
    axis, near its rim); every other block (and the orange one when the penalty spot does not
    apply) is in some bowl."""

    name = "r158"
    description = (
        "Put the orange block in front of the blue bowl if they're both there, that's the penalty "
        "spot. Everything else in bowls."
    )

    @staticmethod
    def _penalty(state) -> bool:
        return has(state, "orange block") and has(state, "blue bowl")

    def _ok(self, s, b) -> bool:
        if b == "orange block" and self._penalty(s):
            return in_front_of_bowl(s, b, "blue bowl", dx_tol=0.04)
        return in_bowl(s, b) is not None

    def satisfied(self, state):
        return bool(state.blocks) and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        return bool(scene.blocks) and bool(scene.bowls)

    def sample_scene(self, rng):
        want_penalty = rng.random() < 0.85
        return sample_with(
            rng,
            lambda s: self.feasible(s)
            and (not want_penalty or (has(s, "orange block") and has(s, "blue bowl") and len(s.blocks) >= 2)),
        )

    def _build(self, state):
        penalty = self._penalty(state)

        def fix(B, b):
            s = B.state
            if b == "orange block" and penalty:
                if B.do(PutNextTo(block=b, target="blue bowl", side="front")) and self._ok(B.state, b):
                    return True
                pts = near_side_points(xy(s, "blue bowl"), "front", 0.035)
                return B.put_at_spot(b, lambda p: True, lambda p: 0, points=pts)
            here = xy(s, b)
            w = min(s.bowls, key=lambda w: (dist(xy(s, w), here), w))
            return B.do(PutIn(block=b, bowl=w))

        return repair(
            state,
            lambda s, b: not self._ok(s, b),
            fix,
            priority=lambda b: 1.0 if b == "orange block" else 0.0,
        )


class R171(_Checker):
    """Reading: every block whose colour matches a bowl stands on the table next to that bowl
    (the world's next-to relation), not in it; blocks without a matching bowl are free."""

    name = "r171"
    description = (
        "Put each block next to the bowl of the same colour but not in it, so I can practise the "
        "final placement with my client."
    )

    @staticmethod
    def _pairs(state) -> list[tuple[str, str]]:
        return [(b, f"{color(b)} bowl") for b in state.blocks if f"{color(b)} bowl" in state.positions]

    @staticmethod
    def _ok(s, b, w) -> bool:
        return on_ground(s, b) and relations(s).is_next_to(b, w)

    def satisfied(self, state):
        pairs = self._pairs(state)
        return bool(pairs) and all(self._ok(state, b, w) for b, w in pairs)

    def _fraction(self, state):
        return _frac([self._ok(state, b, w) for b, w in self._pairs(state)])

    def feasible(self, scene):
        return any(f"{color(b)} bowl" in scene.objects for b in scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible, matching=bool(rng.random() < 0.8) or None)

    def _build(self, state):
        match = dict(self._pairs(state))

        def fix(B, b):
            w = match[b]
            for side in ("nearest", "front", "behind", "left", "right"):
                save = (B.state, len(B.steps))
                if B.do(PutNextTo(block=b, target=w, side=side)) and self._ok(B.state, b, w):
                    return True
                B.state, B.steps = save[0], B.steps[: save[1]]
            c = xy(B.state, w)
            pts = [
                (round(float(c[0] + FRONT_OFFSET * np.cos(a)), 4), round(float(c[1] + FRONT_OFFSET * np.sin(a)), 4))
                for a in np.linspace(0, 2 * np.pi, 48, endpoint=False)
            ]
            here = xy(B.state, b)
            return B.put_at_spot(b, lambda p: True, lambda p: dist(p, here), points=pts)

        return repair(state, lambda s, b: b in match and not self._ok(s, b, match[b]), fix)


class R190(_Checker):
    """Reading: all blocks on the table (none in bowls or stacked) in one horizontal row
    (y within 1 cm) across the middle band (row at -0.58 ≤ y ≤ -0.42, its midpoint within 10 cm of
    the table's centre line), evenly spaced (gaps differ by ≤ 1.5 cm, none overlapping)."""

    name = "r190"
    description = (
        "Just make it look tidy. All the blocks in a straight row across the middle, left to right, "
        "nice and even."
    )

    def _row_ok(self, state) -> bool:
        bl = state.blocks
        if len(bl) < 2 or not all(on_ground(state, b) for b in bl):
            return False
        ps = np.array([xy(state, b) for b in bl])
        ys = ps[:, 1]
        if ys.max() - ys.min() > 0.01 or not -0.58 <= ys.mean() <= -0.42:
            return False
        xs = np.sort(ps[:, 0])
        if abs((xs[0] + xs[-1]) / 2) > 0.1:
            return False
        gaps = np.diff(xs)
        return bool(gaps.min() >= 0.045 and gaps.max() - gaps.min() <= 0.015)

    def satisfied(self, state):
        return self._row_ok(state)

    def _fraction(self, state):
        bl = state.blocks
        if not bl:
            return 0.0
        ymid = float(np.median([state.positions[b][1] for b in bl]))
        ok = [on_ground(state, b) and abs(state.positions[b][1] - ymid) <= 0.005 and -0.58 <= ymid <= -0.42 for b in bl]
        return 0.9 * _frac(ok)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        bl = state.blocks
        n = len(bl)
        ys = sorted(np.arange(-0.57, -0.43 + 1e-9, 0.01), key=lambda y: (abs(y + 0.5), y))
        ds = [0.08, 0.07, 0.09, 0.06, 0.1, 0.11, 0.12, 0.13, 0.14, 0.15]
        xcs = sorted(np.arange(-0.08, 0.08 + 1e-9, 0.01), key=lambda x: (abs(x), x))
        pts = find_even_row(state, set(bl), n, ys, ds, xcs)
        if pts is None:
            return None
        return place_at_points(state, assign_left_to_right(state, bl, pts))


class R191(_Checker):
    """Reading: the red block (pink is not red) goes in the bowl whose centre is furthest left;
    no non-red block may sit in that check bowl; other blocks otherwise free."""

    name = "r191"
    description = (
        "Anything red goes in the bowl furthest to the left. Red means check it, and that's where I "
        "check things."
    )

    def _ok(self, s, b) -> bool:
        w = leftmost_bowl(s)
        if color(b) == "red":
            return in_bowl(s, b) == w
        return in_bowl(s, b) != w

    def satisfied(self, state):
        return self.feasible(state.scene) and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        return "red block" in scene.objects and bool(scene.bowls)

    def sample_scene(self, rng):
        nb = 2 if rng.random() < 0.75 else 1
        return sample_with(rng, self.feasible, n_bowls=nb)

    def _build(self, state):
        w = leftmost_bowl(state)

        def fix(B, b):
            if color(b) == "red":
                return B.do(PutIn(block=b, bowl=w))
            others = [o for o in B.state.bowls if o != w]
            if others:
                here = xy(B.state, b)
                return B.do(PutIn(block=b, bowl=min(others, key=lambda o: dist(xy(B.state, o), here))))
            return B.park(b)

        return repair(state, lambda s, b: not self._ok(s, b), fix, priority=lambda b: 1.0 if color(b) == "red" else 0.0)


class R208(_Checker):
    """Reading: every block ends in the single bowl whose centre is nearest the table's middle
    (0, -0.5); blocks already there are not moved."""

    name = "r208"
    description = "Just put everything in one bowl, whichever bowl is closest to the middle. Fewest moves wins."

    @staticmethod
    def _target(s) -> str | None:
        return min(s.bowls, key=lambda w: (dist(xy(s, w), MIDDLE), w)) if s.bowls else None

    def satisfied(self, state):
        w = self._target(state)
        return w is not None and bool(state.blocks) and all(in_bowl(state, b) == w for b in state.blocks)

    def _fraction(self, state):
        w = self._target(state)
        return _frac([in_bowl(state, b) == w for b in state.blocks])

    def feasible(self, scene):
        return bool(scene.bowls) and bool(scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        w = self._target(state)
        return repair(state, lambda s, b: in_bowl(s, b) != w, lambda B, b: B.do(PutIn(block=b, bowl=w)))


COMPLEMENTS = (("orange", "blue"), ("red", "green"), ("yellow", "purple"))


class R235(_Checker):
    """Reading: for each complementary pair (orange/blue, red/green, yellow/purple) whose two
    blocks are both present, those two blocks stand next to each other on the table (world
    next-to); bowls and other blocks are free."""

    name = "r235"
    description = (
        "complementary colours together pls. orange next to blue, red next to green, yellow next to "
        "purple. whatever pairs show up that day"
    )

    @staticmethod
    def _pairs(objs) -> list[tuple[str, str]]:
        return [(f"{a} block", f"{b} block") for a, b in COMPLEMENTS if f"{a} block" in objs and f"{b} block" in objs]

    @staticmethod
    def _ok(s, a, b) -> bool:
        return on_ground(s, a) and on_ground(s, b) and relations(s).is_next_to(a, b)

    def satisfied(self, state):
        pairs = self._pairs(state.names)
        return bool(pairs) and all(self._ok(state, a, b) for a, b in pairs)

    def _fraction(self, state):
        return _frac([self._ok(state, a, b) for a, b in self._pairs(state.names)])

    def feasible(self, scene):
        return bool(self._pairs(scene.objects))

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        pairs = self._pairs(state.names)
        partner = {}
        for a, b in pairs:
            partner[a], partner[b] = b, a

        def bad(s, x):
            return x in partner and not self._ok(s, x, partner[x])

        def try_next(B, mover, anchor) -> bool:
            if above(B.state, mover) is not None or not loose(B.state, anchor):
                return False
            for side in ("nearest", "left", "right", "front", "behind"):
                save_s, save_n = B.state, len(B.steps)
                if B.do(PutNextTo(block=mover, target=anchor, side=side)) and self._ok(B.state, mover, anchor):
                    return True
                B.state, B.steps = save_s, B.steps[:save_n]
            return False

        def open_spot(B, x):
            # a roomy spot: at least 12 cm from every other object
            here = xy(B.state, x)
            return B.put_at_spot(
                x,
                lambda p: all(dist(p, xy(B.state, o)) >= radius(o) + 0.11 for o in B.state.names if o != x)
                and -0.24 <= p[0] <= 0.24 and -0.74 <= p[1] <= -0.26,
                lambda p: dist(p, here),
            )

        def fix(B, x):
            y = partner[x]
            n0 = len(B.steps)
            for z in (x, y):  # take whatever sits on either block off first
                while (top := topmost_above(B.state, z)) is not None:
                    if not B.park(top):
                        return len(B.steps) > n0
            if try_next(B, x, y) or try_next(B, y, x):
                return True
            # no room beside either one where it stands: bring one of them to a roomy spot first
            for anchor, mover in ((y, x), (x, y)):
                if open_spot(B, anchor) and (try_next(B, mover, anchor)):
                    return True
            return len(B.steps) > n0

        return repair(state, bad, fix)


def _at_edge(p, margin: float = 0.0) -> bool:
    x, y = p[0], p[1]
    return x <= -0.2 - margin or x >= 0.2 + margin or y <= -0.7 - margin or y >= -0.3 + margin


class R251(_Checker):
    """Reading: the green block is within 5 cm of the table centre (0, -0.5) with nothing on it,
    standing on the table, or alone in a bowl when that bowl sits at the centre; every other block
    lies within 10 cm of a table edge (the outer ring); bowls stay where they are."""

    name = "r251"
    description = "Green block dead centre, all by itself. Everything else out at the edges."

    def _ok(self, s, b) -> bool:
        if b == "green block":
            if dist(xy(s, b), MIDDLE) > 0.05 or above(s, b) is not None:
                return False
            w = in_bowl(s, b)
            return loose(s, b) if w is None else bowl_blocks(s, w) == [b]
        return _at_edge(xy(s, b))

    def satisfied(self, state):
        return "green block" in state.positions and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        return "green block" in scene.objects

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible, n_blocks=(2, 3), n_bowls=(0, 2))

    def _build(self, state):
        centre_pts = _grid(0.005, (-0.045, 0.045), (-0.545, -0.455))

        def fix(B, b):
            if b == "green block":
                if B.put_at_spot(b, lambda p: dist(p, MIDDLE) <= 0.045, lambda p: dist(p, MIDDLE), points=centre_pts):
                    return True
                for w in B.state.bowls:  # a bowl sits on the centre: the green block alone in it
                    if dist(xy(B.state, w), MIDDLE) <= 0.05 and not bowl_blocks(B.state, w):
                        return B.do(PutIn(block=b, bowl=w))
                return False
            here = xy(B.state, b)
            return B.put_at_spot(b, lambda p: _at_edge(p, 0.02), lambda p: dist(p, here))

        return repair(
            state,
            lambda s, b: not self._ok(s, b),
            fix,
            priority=lambda b: 1.0 if b == "green block" else 0.0,
            avoid=lambda p: dist(p, MIDDLE) < 0.12,
        )


def _row_line_ok(state, y_lo, y_hi, spread) -> bool:
    bl = state.blocks
    if not bl or not all(on_ground(state, b) for b in bl):
        return False
    ps = np.array([xy(state, b) for b in bl])
    ys = ps[:, 1]
    if ys.max() - ys.min() > spread or ys.min() < y_lo or ys.max() > y_hi:
        return False
    xs = np.sort(ps[:, 0])
    return bool(len(xs) < 2 or np.diff(xs).min() >= 0.044)


class R252(_Checker):
    """Reading: every block out of the bowls, on the table, in one row (y within 1.5 cm, blocks
    side by side, not overlapping) within 10 cm of the front edge (y ≤ -0.70); bowls untouched."""

    name = "r252"
    description = (
        "make it a palette: all the blocks in a row along the front edge, bowls are the water jars, "
        "don't touch them"
    )

    def satisfied(self, state):
        return _row_line_ok(state, -0.82, -0.70, 0.015)

    def _fraction(self, state):
        return 0.9 * _frac([on_ground(state, b) and state.positions[b][1] <= -0.70 for b in state.blocks])

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        bl = state.blocks
        ys = [-0.76, -0.75, -0.77, -0.74, -0.78, -0.73, -0.72]
        pts = find_even_row(
            state, set(bl), len(bl), ys, [0.07, 0.06, 0.08, 0.09, 0.1],
            sorted(np.arange(-0.2, 0.2 + 1e-9, 0.01), key=lambda x: (abs(x), x)),
        ) or find_greedy_row(state, set(bl), len(bl), ys)
        if pts is None:
            return None
        return place_at_points(state, assign_left_to_right(state, bl, pts))


class R253(_Checker):
    """Reading: every block is in the back third of the table (centre y ≥ -0.40, the top row of
    the 3×3 grid), whether on the table, stacked or in a bowl there."""

    name = "r253"
    description = (
        "Nothing near the front edge. The dogs put their noses on the table. Keep all the blocks at the back."
    )

    @staticmethod
    def _ok(s, b) -> bool:
        return s.positions[b][1] >= -0.40

    def satisfied(self, state):
        return bool(state.blocks) and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        return bool(scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, lambda s: self.feasible(s) and len(s.blocks) >= 2)

    def _build(self, state):
        def fix(B, b):
            here = xy(B.state, b)
            return B.put_at_spot(b, lambda p: p[1] >= -0.385, lambda p: (dist(p, here), p))

        return repair(state, lambda s, b: not self._ok(s, b), fix)


class R256(_Checker):
    """Reading: the red block is in the bowl whose centre is furthest right, and no other block is
    in that bowl; other blocks are otherwise free."""

    name = "r256"
    description = (
        "Red block always goes in a bowl on its own, the one furthest to the right. Treat it like a "
        "biohazard bag."
    )

    def _ok(self, s, b) -> bool:
        w = rightmost_bowl(s)
        if b == "red block":
            return in_bowl(s, b) == w
        return in_bowl(s, b) != w

    def satisfied(self, state):
        return self.feasible(state.scene) and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        return "red block" in scene.objects and bool(scene.bowls)

    def sample_scene(self, rng):
        nb = 2 if rng.random() < 0.75 else 1
        return sample_with(rng, self.feasible, n_bowls=nb)

    def _build(self, state):
        w = rightmost_bowl(state)

        def fix(B, b):
            if b == "red block":
                return B.do(PutIn(block=b, bowl=w))
            here = xy(B.state, w)
            return B.put_at_spot(b, lambda p: dist(p, here) > 0.12, lambda p: (dist(p, here), p))

        return repair(state, lambda s, b: not self._ok(s, b), fix, priority=lambda b: 1.0 if b == "red block" else 0.0)


class R267(_Checker):
    """Reading: with the world's warm/cool palette, every cool block lies in the back-right corner
    cell of the 3×3 grid (x ≥ 0.1, y ≥ -0.4) and every warm block in the front-left corner cell
    (x ≤ -0.1, y ≤ -0.6), whether on the table, stacked or in a bowl there."""

    name = "r267"
    description = "Cool colours in the back right corner by the window, warm colours in the front left."

    @staticmethod
    def _want(b) -> str:
        return "top right corner" if color(b) in COOL_COLORS else "bottom left corner"

    def _ok(self, s, b) -> bool:
        return table_position_name(xy(s, b)) == self._want(b)

    def satisfied(self, state):
        return bool(state.blocks) and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        cols = {color(b) for b in scene.blocks}
        return bool(cols & WARM_COLORS) and bool(cols & COOL_COLORS)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        def fix(B, b):
            if color(b) in COOL_COLORS:
                corner, pred = (0.26, -0.24), (lambda p: p[0] >= 0.115 and p[1] >= -0.385)
            else:
                corner, pred = (-0.26, -0.76), (lambda p: p[0] <= -0.115 and p[1] <= -0.615)
            if B.put_at_spot(b, pred, lambda p: (dist(p, corner), p)):
                return True
            want = self._want(b)
            for o in B.state.blocks:  # stack on a block already in the corner
                if o != b and above(B.state, o) is None and self._ok(B.state, o) and self._want(o) == want:
                    if B.do(PutOn(block=b, target=o)):
                        return True
            for w in B.state.bowls:
                if table_position_name(xy(B.state, w)) == want and B.do(PutIn(block=b, bowl=w)):
                    return True
            return False

        return repair(state, lambda s, b: not self._ok(s, b), fix)


class R268(_Checker):
    """Reading: each bowl gets exactly one block standing on the table directly in front of it
    (within 3 cm of its axis, near its front rim) as its label; a block of the bowl's colour, when
    there is one, must be that bowl's label; spare blocks must not stand in front of any bowl."""

    name = "r268"
    description = (
        "Label everything, like at work: put one block directly in front of each bowl so I know "
        "which bowl is which."
    )

    @staticmethod
    def _labels_in_front(s, w) -> list[str]:
        return [b for b in s.blocks if in_front_of_bowl(s, b, w)]

    def _bowl_ok(self, s, w) -> bool:
        labels = self._labels_in_front(s, w)
        if len(labels) != 1:
            return False
        same = f"{color(w)} block"
        return same not in s.positions or labels[0] == same

    def satisfied(self, state):
        return self.feasible(state.scene) and all(self._bowl_ok(state, w) for w in state.bowls)

    def _fraction(self, state):
        return _frac([self._bowl_ok(state, w) for w in state.bowls])

    def feasible(self, scene):
        return 1 <= len(scene.bowls) <= len(scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible, matching=True if rng.random() < 0.5 else None)

    def _assign(self, state) -> dict[str, str]:
        """bowl → label block."""
        out: dict[str, str] = {}
        reserved = {f"{color(w)} block" for w in state.bowls} & set(state.blocks)
        for w in state.bowls:
            if f"{color(w)} block" in state.positions:
                out[w] = f"{color(w)} block"
        free = [b for b in state.blocks if b not in reserved]
        for w in sorted(state.bowls, key=lambda w: (state.positions[w][0], w)):
            if w in out:
                continue
            spot = xy(state, w) - np.array([0.0, FRONT_OFFSET])
            # prefer one already in front, else the nearest spare block
            b = min(free, key=lambda b: (not in_front_of_bowl(state, b, w), dist(xy(state, b), spot), b))
            free.remove(b)
            out[w] = b
        return out

    def _build(self, state):
        label_of = self._assign(state)
        bowl_of = {b: w for w, b in label_of.items()}
        fronts = [xy(state, w) - np.array([0.0, FRONT_OFFSET]) for w in state.bowls]

        def in_front_any(s, b):
            return any(in_front_of_bowl(s, b, w) for w in s.bowls)

        def bad(s, b):
            if b in bowl_of:
                return not in_front_of_bowl(s, b, bowl_of[b])
            return in_front_any(s, b)

        def fix(B, b):
            if b not in bowl_of:
                here = xy(B.state, b)
                return B.put_at_spot(
                    b,
                    lambda p: all(dist(p, f) > 0.09 for f in fronts),
                    lambda p: (dist(p, here), p),
                )
            w = bowl_of[b]
            save_s, save_n = B.state, len(B.steps)
            if B.do(PutNextTo(block=b, target=w, side="front")) and in_front_of_bowl(B.state, b, w):
                return True
            B.state, B.steps = save_s, B.steps[:save_n]
            return B.put_at_spot(b, lambda p: True, lambda p: 0, points=near_side_points(xy(B.state, w), "front", 0.025))

        def unblock(B, todo):
            for b in todo:
                if b not in bowl_of:
                    continue
                f = xy(B.state, bowl_of[b]) - np.array([0.0, FRONT_OFFSET])
                for o in B.state.blocks:
                    if o != b and dist(xy(B.state, o), f) < 0.05 and above(B.state, o) is None:
                        if B.park(o, lambda p: any(dist(p, g) < 0.09 for g in fronts)):
                            return True
            return False

        return repair(state, bad, fix, priority=lambda b: 1.0 if b in bowl_of else 0.0,
                      avoid=lambda p: any(dist(p, g) < 0.09 for g in fronts), unblock=unblock)


class R273(_Checker):
    """Reading: every block is inside some bowl (any bowl, piles allowed)."""

    name = "r273"
    description = (
        "Put all the blocks into bowls so nothing's loose. Any bowl is fine, I just don't want cubes "
        "rolling around."
    )

    def satisfied(self, state):
        return bool(state.blocks) and all(in_bowl(state, b) is not None for b in state.blocks)

    def _fraction(self, state):
        return _frac([in_bowl(state, b) is not None for b in state.blocks])

    def feasible(self, scene):
        return bool(scene.bowls) and bool(scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        def fix(B, b):
            s = B.state
            here = xy(s, b)
            w = min(s.bowls, key=lambda w: (len(bowl_blocks(s, w)), dist(xy(s, w), here), w))
            return B.do(PutIn(block=b, bowl=w))

        return repair(state, lambda s, b: in_bowl(s, b) is None, fix)


class R277(_Checker):
    """Reading: all blocks form one single tower whose bottom block stands in a back corner cell of
    the 3×3 grid (back-left or back-right: |x| ≥ 0.1, y ≥ -0.4)."""

    name = "r277"
    description = (
        "Stack them all in one tower in the back corner, far from the front where little hands reach."
    )

    @staticmethod
    def _in_back_corner(p) -> bool:
        return table_position_name(p) in ("top left corner", "top right corner")

    def satisfied(self, state):
        h = tower_heights(state)
        if len(h) != 1 or len(state.blocks) < 2:
            return False
        base, height = next(iter(h.items()))
        return height == len(state.blocks) and self._in_back_corner(xy(state, base))

    def _fraction(self, state):
        h = tower_heights(state)
        if not h:
            return 0.0
        best = max(h, key=lambda b: (h[b], self._in_back_corner(xy(state, b))))
        f = h[best] / len(state.blocks)
        return f * (1.0 if self._in_back_corner(xy(state, best)) else 0.5)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        B = Builder(state)
        corners = [(-0.25, -0.25), (0.25, -0.25)]
        pred = lambda p: abs(p[0]) >= 0.115 and p[1] >= -0.385  # noqa: E731
        # base: a loose block already in a back corner, else the free block nearest a free corner spot
        base = next((b for b in state.blocks if loose(state, b) and self._in_back_corner(xy(state, b))), None)
        if base is None:
            cands = sorted(
                (b for b in state.blocks if above(state, b) is None),
                key=lambda b: (min(dist(xy(state, b), c) for c in corners), b),
            )
            for b in cands:
                here = xy(state, b)
                near = min(corners, key=lambda c: dist(c, here))
                if B.put_at_spot(b, pred, lambda p: (dist(p, near), dist(p, here))):
                    base = b
                    break
            if base is None:
                return None
        tower = [base]
        for _ in range(4 * len(state.blocks) + 4):
            rest = [b for b in B.state.blocks if b not in tower]
            if not rest:
                return B
            movable = [b for b in rest if above(B.state, b) is None]
            moved = False
            for b in sorted(movable, key=lambda b: (-B.state.positions[b][2], b)):
                if B.do(PutOn(block=b, target=tower[-1])):
                    tower.append(b)
                    moved = True
                    break
            if not moved:
                return None
        return None


class R286(_Checker):
    """Reading: build towers but never taller than two: at least one two-block tower exists and
    no pile (on the table or in a bowl) is three or more blocks high."""

    name = "r286"
    description = "Towers no higher than two. Anything taller and they topple it on purpose."

    def satisfied(self, state):
        h = tower_heights(state)
        return bool(h) and max(h.values()) <= 2 and 2 in h.values()

    def _fraction(self, state):
        h = tower_heights(state)
        if not h:
            return 0.0
        ok = sum(v for v in h.values() if v <= 2) / len(state.blocks)
        return ok * (1.0 if 2 in h.values() else 0.5)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        B = Builder(state)

        def level(s, b):
            n, cur = 1, below(s, b)
            while cur is not None:
                n, cur = n + 1, below(s, cur)
            return n

        for _ in range(20):  # take down everything above the second level
            high = [b for b in B.state.blocks if level(B.state, b) >= 3 and above(B.state, b) is None]
            if not high:
                break
            if not B.park(high[0]):
                return None
        for _ in range(10):  # pair up single blocks into towers of two
            singles = [b for b in B.state.blocks if above(B.state, b) is None and below(B.state, b) is None]
            if len(singles) < 2:
                break
            best = min(
                ((a, b) for a in singles for b in singles if a != b),
                key=lambda ab: (dist(xy(B.state, ab[0]), xy(B.state, ab[1])), ab),
            )
            if not B.do(PutOn(block=best[0], target=best[1])):
                return None
        if not self.satisfied(B.state):  # all blocks already in towers of two except high ones
            return None
        return B


class R321(_Checker):
    """Reading: every block whose colour matches a bowl stands on the table immediately to the
    right of that bowl (x larger, within 3 cm of its centre line, near its rim); other blocks free."""

    name = "r321"
    description = (
        "Blocks go next to their matching bowl, always on the right side of it. Consistent "
        "placement, fewer mistakes."
    )

    @staticmethod
    def _pairs(state) -> list[tuple[str, str]]:
        return [(b, f"{color(b)} bowl") for b in state.blocks if f"{color(b)} bowl" in state.positions]

    def satisfied(self, state):
        pairs = self._pairs(state)
        return bool(pairs) and all(right_of_bowl(state, b, w) for b, w in pairs)

    def _fraction(self, state):
        return _frac([right_of_bowl(state, b, w) for b, w in self._pairs(state)])

    def feasible(self, scene):
        return any(f"{color(b)} bowl" in scene.objects for b in scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible, matching=bool(rng.random() < 0.8) or None)

    def _build(self, state):
        match = dict(self._pairs(state))
        rights = [xy(state, w) + np.array([FRONT_OFFSET, 0.0]) for w in match.values()]

        def fix(B, b):
            w = match[b]
            save_s, save_n = B.state, len(B.steps)
            if B.do(PutNextTo(block=b, target=w, side="right")) and right_of_bowl(B.state, b, w):
                return True
            B.state, B.steps = save_s, B.steps[:save_n]
            return B.put_at_spot(b, lambda p: True, lambda p: 0, points=near_side_points(xy(B.state, w), "right", 0.025))

        def unblock(B, todo):
            for b in todo:
                f = xy(B.state, match[b]) + np.array([FRONT_OFFSET, 0.0])
                for o in B.state.blocks:
                    if o != b and dist(xy(B.state, o), f) < 0.05 and above(B.state, o) is None:
                        if B.park(o, lambda p: any(dist(p, g) < 0.09 for g in rights)):
                            return True
            return False

        return repair(state, lambda s, b: b in match and not right_of_bowl(s, b, match[b]), fix,
                      avoid=lambda p: any(dist(p, g) < 0.09 for g in rights), unblock=unblock)


class R323(_Checker):
    """Reading: the red block stands out of any bowl, nearer the front edge than everything else:
    its centre is at or in front of the front edge of every other block and bowl."""

    name = "r323"
    description = (
        "Just put the red one in front of everything else. Red's my race-day colour, first thing I "
        "want to see."
    )

    @staticmethod
    def _front_edge(s, o) -> float:
        return s.positions[o][1] - radius(o)

    def satisfied(self, state):
        if "red block" not in state.positions or in_bowl(state, "red block") is not None:
            return False
        ry = state.positions["red block"][1]
        return all(ry <= self._front_edge(state, o) + 1e-6 for o in state.names if o != "red block")

    def _fraction(self, state):
        if "red block" not in state.positions:
            return 0.0
        ry = state.positions["red block"][1]
        others = [o for o in state.names if o != "red block"]
        return 0.9 * _frac([ry <= self._front_edge(state, o) for o in others])

    def feasible(self, scene):
        return "red block" in scene.objects and len(scene.objects) >= 3

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        R = "red block"

        def bad(s, b):
            if b == R:
                return not self.satisfied(s)
            return s.positions[b][1] - HALF < -0.775  # would stand in front of the red block's spot

        def fix(B, b):
            if b == R:
                return B.put_at_spot(b, lambda p: p[1] <= -0.775, lambda p: (abs(p[0]), p[0]))
            here = xy(B.state, b)
            return B.put_at_spot(b, lambda p: p[1] >= -0.70, lambda p: (dist(p, here), p))

        return repair(state, bad, fix, priority=lambda b: 1.0 if b == R else 0.0)


class R327(_Checker):
    """Reading: every block out of the bowls, on the table, in one straight row parallel to the
    back edge (y within 8 mm) within 10 cm of the back edge (y ≥ -0.30), side by side without
    overlap; bowls cannot move and are ignored."""

    name = "r327"
    description = "Line everything up square along the back edge. I like a straight line, nothing crooked."

    def satisfied(self, state):
        return _row_line_ok(state, -0.30, -0.18, 0.008)

    def _fraction(self, state):
        return 0.9 * _frac([on_ground(state, b) and state.positions[b][1] >= -0.30 for b in state.blocks])

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        bl = state.blocks
        ys = [-0.24, -0.25, -0.23, -0.26, -0.22, -0.27, -0.28]
        pts = find_even_row(
            state, set(bl), len(bl), ys, [0.07, 0.06, 0.08, 0.09, 0.1],
            sorted(np.arange(-0.2, 0.2 + 1e-9, 0.01), key=lambda x: (abs(x), x)),
        ) or find_greedy_row(state, set(bl), len(bl), ys)
        if pts is None:
            return None
        return place_at_points(state, assign_left_to_right(state, bl, pts))


class R331(_Checker):
    """Reading: no block (on the table or in a bowl) lies in the right third of the table: every
    block's whole footprint is left of x = 0.10 (centre x ≤ 0.08); bowls cannot move."""

    name = "r331"
    description = "Keep the right side of the table clear, that's where my tools go when I'm sketching."

    @staticmethod
    def _ok(s, b) -> bool:
        return s.positions[b][0] <= 0.08

    def satisfied(self, state):
        return bool(state.blocks) and all(self._ok(state, b) for b in state.blocks)

    def _fraction(self, state):
        return _frac([self._ok(state, b) for b in state.blocks])

    def feasible(self, scene):
        return bool(scene.blocks)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible)

    def _build(self, state):
        def fix(B, b):
            here = xy(B.state, b)
            return B.put_at_spot(b, lambda p: p[0] <= 0.0, lambda p: (dist(p, here), p)) or B.put_at_spot(
                b, lambda p: p[0] <= 0.06, lambda p: (dist(p, here), p)
            )

        return repair(state, lambda s, b: not self._ok(s, b), fix, avoid=lambda p: p[0] > 0.06)


PLAIN = frozenset({"gray", "brown"})


class R335(_Checker):
    """Reading: all gray/brown blocks share one bowl and all other blocks share one other bowl
    (two different bowls; any bowls, e.g. the gray/brown bowl for the plain ones when present)."""

    name = "r335"
    description = "Sort them: plain colours (gray, brown) in one bowl, everything else in another."

    @staticmethod
    def _groups(state):
        plain = [b for b in state.blocks if color(b) in PLAIN]
        other = [b for b in state.blocks if color(b) not in PLAIN]
        return plain, other

    def satisfied(self, state):
        plain, other = self._groups(state)
        if not state.blocks:
            return False
        pb = {in_bowl(state, b) for b in plain}
        ob = {in_bowl(state, b) for b in other}
        if None in pb or None in ob or len(pb) > 1 or len(ob) > 1:
            return False
        return not (pb and ob) or pb != ob

    def _fraction(self, state):
        plain, other = self._groups(state)
        best = 0.0
        for p in state.bowls:
            for q in state.bowls:
                if p == q and plain and other:
                    continue
                ok = [in_bowl(state, b) == p for b in plain] + [in_bowl(state, b) == q for b in other]
                best = max(best, _frac(ok))
        return best

    def feasible(self, scene):
        cols = {color(b) for b in scene.blocks}
        return len(scene.bowls) >= 2 and bool(cols & PLAIN) and bool(cols - PLAIN)

    def sample_scene(self, rng):
        return sample_with(rng, self.feasible, n_bowls=2)

    def _build(self, state):
        plain, other = self._groups(state)
        best = None
        for p in state.bowls:
            for q in state.bowls:
                if p == q:
                    continue
                moves = sum(in_bowl(state, b) != p for b in plain) + sum(in_bowl(state, b) != q for b in other)
                pref = (color(p) not in PLAIN, color(q) in PLAIN)  # plain bowl colours for plain blocks
                k = (moves, pref, p, q)
                if best is None or k < best:
                    best = k
        _, _, p, q = best
        target = {b: p for b in plain} | {b: q for b in other}
        return repair(state, lambda s, b: in_bowl(s, b) != target[b], lambda B, b: B.do(PutIn(block=b, bowl=target[b])))


CHECKERS = [
    R158, R171, R190, R191, R208, R235, R251, R252, R253, R256,
    R267, R268, R273, R277, R286, R321, R323, R327, R331, R335,
]
