"""Checkers for the pass-3 translation check, writer e3: request text and the world's public API only."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_RADIUS,
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
    table_position_name,
    target_position,
)

# ----------------------------------------------------------------------------------------------
# Geometry of the table (x: left -> right, y: front/bottom -> back/top).
# "front" = bottom side of the table (small y), "back"/"behind" = top side (large y).
# ----------------------------------------------------------------------------------------------

(X0, X1), (Y0, Y1) = BOUNDS
HALF = BLOCK_SIZE / 2
EDGE = HALF + 0.005  # keep block centres this far inside the table edges when planning
XMIN, XMAX = X0 + EDGE, X1 - EDGE
YMIN, YMAX = Y0 + EDGE, Y1 - EDGE
CX, CY = (X0 + X1) / 2, (Y0 + Y1) / 2  # table centre (0, -0.5)
THIRD_X = (X1 - X0) / 3
THIRD_Y = (Y1 - Y0) / 3
LEFT_LINE, RIGHT_LINE = X0 + THIRD_X, X1 - THIRD_X  # -0.1, 0.1
FRONT_LINE, BACK_LINE = Y0 + THIRD_Y, Y1 - THIRD_Y  # -0.6, -0.4
CORNER_CELLS = {"top left corner", "top right corner", "bottom left corner", "bottom right corner"}
BLOCK_CLEAR = BLOCK_SIZE + 0.006  # two blocks side by side on the table need this centre distance


def _fp(name: str) -> float:
    return BOWL_RADIUS if WorldState.kind(name) == "bowl" else HALF


def _xy(state: WorldState, name: str) -> tuple[float, float]:
    p = state.positions[name]
    return float(p[0]), float(p[1])


def _z(state: WorldState, name: str) -> float:
    return float(state.positions[name][2])


def _cell(state: WorldState, name: str) -> str:
    return table_position_name(_xy(state, name))


def _dist(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _blocks_of(state: WorldState, color: str) -> str | None:
    n = f"{color} block"
    return n if n in state.positions else None


def _matching_pairs(state_or_scene) -> list[tuple[str, str]]:
    objs = list(state_or_scene.positions) if isinstance(state_or_scene, WorldState) else list(state_or_scene.objects)
    return [
        (o, f"{o.split(' ')[0]} bowl")
        for o in objs
        if o.endswith(" block") and f"{o.split(' ')[0]} bowl" in objs
    ]


def _points(x0: float, x1: float, y0: float, y1: float, step: float = 0.01) -> list[tuple[float, float]]:
    """Grid points in [x0, x1] × [y0, y1], clipped to where a block sits wholly on the table."""
    x0, x1 = max(x0, XMIN), min(x1, XMAX)
    y0, y1 = max(y0, YMIN), min(y1, YMAX)
    if x0 > x1 + 1e-9 or y0 > y1 + 1e-9:
        return []
    xs = np.arange(x0, x1 + 1e-9, step)
    ys = np.arange(y0, y1 + 1e-9, step)
    return [(round(float(x), 4), round(float(y), 4)) for x in xs for y in ys]


def _by_dist(points: Iterable[tuple[float, float]], ref: tuple[float, float]) -> list[tuple[float, float]]:
    return sorted(points, key=lambda p: (_dist(p, ref), p))


def _ring(center: tuple[float, float], radii: Iterable[float], n: int = 24) -> list[tuple[float, float]]:
    out = []
    for r in radii:
        for k in range(n):
            a = 2 * math.pi * k / n
            x, y = center[0] + r * math.cos(a), center[1] + r * math.sin(a)
            if XMIN <= x <= XMAX and YMIN <= y <= YMAX:
                out.append((round(x, 4), round(y, 4)))
    return out


def _ring_pts(center: tuple[float, float], here: tuple[float, float]) -> list[tuple[float, float]]:
    """Points just outside a bowl (close ring first), each ring ordered by distance to ``here``."""
    out: list[tuple[float, float]] = []
    for radii in ((0.097,), (0.105,), (0.115, 0.125)):
        out += _by_dist(_ring(center, radii, 24), here)
    return out


# ----------------------------------------------------------------------------------------------
# Execution helpers (all through the world's apply_skill)
# ----------------------------------------------------------------------------------------------


def _try(state: WorldState, step: Skill) -> WorldState | None:
    new, fail = apply_skill(state, step)
    return None if fail is not None else new


def _noop(state: WorldState, step: Skill) -> bool:
    t = target_position(state, step)
    if not isinstance(t, tuple):
        return False
    return bool(np.allclose(t, state.positions[step.block], atol=1e-6))


def _simulate(state: WorldState, steps: list[Skill]) -> WorldState | None:
    for s in steps:
        state = _try(state, s)
        if state is None:
            return None
    return state


def _put_first(state: WorldState, block: str, points: Iterable[tuple[float, float]]):
    """PutAt the first point that works: (new state, step) or None."""
    for p in points:
        step = PutAt(block=block, position=(float(p[0]), float(p[1])))
        new = _try(state, step)
        if new is not None:
            return new, step
    return None


def _above_chain(state: WorldState, block: str) -> list[str]:
    rel = relations(state)
    out: list[str] = []
    cur = block
    while (a := rel.above(cur)) is not None and a not in out and a != block:
        out.append(a)
        cur = a
    return out


_ALL_PTS = None


def _all_points() -> list[tuple[float, float]]:
    global _ALL_PTS
    if _ALL_PTS is None:
        _ALL_PTS = _points(XMIN, XMAX, YMIN, YMAX, 0.02)
    return _ALL_PTS


def _park(state: WorldState, block: str, ok: Callable[[tuple[float, float]], bool] | None = None):
    """Move ``block`` to the nearest free spot on the table (where ``ok`` holds)."""
    pts = [p for p in _all_points() if ok is None or ok(p)]
    return _put_first(state, block, _by_dist(pts, _xy(state, block)))


def _clear(state: WorldState, block: str, steps: list[Skill], ok=None) -> WorldState | None:
    """Park everything stacked on ``block`` (top first)."""
    for a in reversed(_above_chain(state, block)):
        r = _park(state, a, ok)
        if r is None:
            return None
        state, st = r
        steps.append(st)
    return state


def _execute(state: WorldState, steps: list[Skill]):
    """Run ``steps`` in some order that works (blocks under others wait); skip no-ops.
    Returns (final state, executed steps) or None."""
    pending = list(steps)
    out: list[Skill] = []
    while pending:
        for i, st in enumerate(pending):
            if _noop(state, st):
                pending.pop(i)
                break
            new = _try(state, st)
            if new is not None:
                state = new
                out.append(st)
                pending.pop(i)
                break
        else:
            return None
    return state, out


def _top_down(state: WorldState, blocks: Iterable[str]) -> list[str]:
    return sorted(blocks, key=lambda b: -_z(state, b))


def _flatten(state: WorldState, steps: list[Skill], bad) -> WorldState | None:
    """Park, one at a time (top first), every clear block for which ``bad(state, rel, block)`` holds,
    until none is left (used to undo stacks that stand in the way)."""
    for _ in range(4 * len(state.blocks) + 4):
        rel = relations(state)
        cands = [b for b in _top_down(state, state.blocks) if rel.above(b) is None and bad(state, rel, b)]
        if not cands:
            return state
        r = _park(state, cands[0])
        if r is None:
            return None
        state, s = r
        steps.append(s)
    return None


def _on_loose_block(state, rel, b) -> bool:
    return rel.below(b) is not None and rel.in_bowl(b) is None


def _row_slot_sets(state: WorldState, movers: list[str], y: float, n: int, pitch: float = 0.056,
                   ref_x: float = 0.0, xlo: float = XMIN, xhi: float = XMAX, limit: int = 12):
    """Sets of n x positions on the line y, free of every object that is not a mover."""
    static = [
        o for o in state.positions
        if o not in movers and not (WorldState.kind(o) == "block" and _z(state, o) > BLOCK_SIZE)
    ]
    xs = []
    for x in np.arange(xlo, xhi + 1e-9, 0.005):
        x = round(float(x), 4)
        if all(_dist((x, y), _xy(state, o)) >= _fp(o) + HALF + 0.006 for o in static):
            xs.append(x)
    sets = []
    for i, start in enumerate(xs):
        chosen = [start]
        for x in xs[i + 1:]:
            if len(chosen) == n:
                break
            if x >= chosen[-1] + pitch - 1e-9:
                chosen.append(x)
        if len(chosen) == n:
            sets.append(chosen)
    sets.sort(key=lambda s: (round(s[-1] - s[0], 3), abs((s[0] + s[-1]) / 2 - ref_x)))
    return sets[:limit]


def _row_plan(state: WorldState, ordered: list[str], ys: Iterable[float], ok: Callable[[WorldState], bool],
              pre: list[Skill] | None = None, ref_x: float = 0.0, pitch: float = 0.056):
    """Put ``ordered`` blocks in a left-to-right row on one of the lines ``ys``."""
    pre = list(pre or [])
    if not ordered:
        return pre if ok(state) else None
    for y in ys:
        y = round(float(y), 4)
        for xs in _row_slot_sets(state, ordered, y, len(ordered), pitch=pitch, ref_x=ref_x):
            steps = [PutAt(block=b, position=(x, y)) for b, x in zip(ordered, xs)]
            r = _execute(state, steps)
            if r is not None and ok(r[0]):
                return pre + r[1]
    return None


def _is_row(state: WorldState, blocks: list[str], tol: float = 0.015) -> list[bool]:
    """Per block: on the table (not stacked, not in a bowl) and on a common line y (± tol)."""
    if not blocks:
        return []
    rel = relations(state)
    ys = [_xy(state, b)[1] for b in blocks]
    med = float(np.median(ys))
    return [b in rel.on_table and abs(y - med) <= tol for b, y in zip(blocks, ys)]


def _sample(rng: np.random.Generator, ok: Callable[[Scene], bool], n_blocks=(2, 3), n_bowls=(1, 2),
            matching=None, tries: int = 20000) -> Scene:
    for _ in range(tries):
        s = sample_scene(rng, n_blocks=n_blocks, n_bowls=n_bowls, matching=matching)
        if ok(s):
            return s
    raise RuntimeError("no feasible scene found")


class _Checker(Intention):
    """Shared machinery: satisfied = every per-block item holds (and the whole-table condition);
    score = fraction of items that hold (below 1 whenever not satisfied)."""

    sample_kw: dict = {}

    def _items(self, state: WorldState) -> list[bool]:
        raise NotImplementedError

    def _whole(self, state: WorldState) -> bool:
        return True

    def _plan(self, state: WorldState) -> list[Skill] | None:
        raise NotImplementedError

    def satisfied(self, state: WorldState) -> bool:
        return all(self._items(state)) and self._whole(state)

    def score(self, state: WorldState) -> float:
        items = self._items(state)
        s = sum(items) / len(items) if items else 1.0
        if not (all(items) and self._whole(state)):
            s = min(s, 1.0 - 1.0 / (2 * max(1, len(items))))
        return float(max(0.0, min(1.0, s)))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return _sample(rng, self.feasible, **self.sample_kw)

    def plan(self, state: WorldState) -> list[Skill] | None:
        if self.satisfied(state):
            return []
        steps = self._plan(state)
        if steps is None:
            return None
        final = _simulate(state, steps)
        if final is None or not self.satisfied(final):
            return None
        return list(steps)


# ---------------------------------------------------------------------------------------------- helpers
# shared by several requests


def _all_in_bowl_plan(state: WorldState, bowl_for: Callable[[WorldState, str], str | None]):
    steps = []
    for b in state.blocks:
        w = bowl_for(state, b)
        if w is not None:
            steps.append(PutIn(block=b, bowl=w))
    r = _execute(state, steps)
    return None if r is None else r[1]


def _nearest_bowl(state: WorldState, b: str) -> str | None:
    rel = relations(state)
    if rel.in_bowl(b):
        return None
    if not state.bowls:
        return None
    return min(state.bowls, key=lambda w: _dist(_xy(state, w), _xy(state, b)))


def _single_to_region(state: WorldState, block: str, pts: list[tuple[float, float]], in_region) -> list[Skill] | None:
    """Move one block into a region (nearest free point of ``pts``), clearing what sits on it."""
    steps: list[Skill] = []
    st = _clear(state, block, steps, ok=lambda p: not in_region(p))
    if st is None:
        return None
    r = _put_first(st, block, pts)
    if r is None:
        return None
    return steps + [r[1]]


def _blocks_to_region(state: WorldState, blocks: list[str], pts_for: Callable[[WorldState, str], list],
                      stack_fallback: Callable[[WorldState], list[Skill]] | None = None):
    """Greedily move each block (top first) to the first free point from pts_for(state, block)."""
    steps: list[Skill] = []
    st = state
    for b in _top_down(state, blocks):
        r = _put_first(st, b, pts_for(st, b))
        if r is None:
            if stack_fallback is None:
                return None
            for cand in stack_fallback(st, b):
                new = _try(st, cand)
                if new is not None:
                    r = (new, cand)
                    break
            else:
                return None
        st, step = r
        steps.append(step)
    return steps


# ============================================================================================== requests


class R326(_Checker):
    """Reading: if a brown bowl is on the table, every block ends up inside it (stacked in it is fine);
    without a brown bowl nothing is asked."""

    name = "r326"
    description = "All blocks into the brown bowl if it's there. Looks like wood, suits me."

    def feasible(self, scene: Scene) -> bool:
        return "brown bowl" in scene.bowls and len(scene.blocks) >= 1

    def _items(self, state):
        if "brown bowl" not in state.positions:
            return [True for _ in state.blocks]
        rel = relations(state)
        return [rel.in_bowl(b) == "brown bowl" for b in state.blocks]

    def _plan(self, state):
        if "brown bowl" not in state.positions:
            return []
        rel = relations(state)
        return _all_in_bowl_plan(
            state, lambda s, b: None if rel.in_bowl(b) == "brown bowl" else "brown bowl"
        )


class R031(_Checker):
    """Reading: every block rests (not in a bowl) in the middle cell of the 3×3 table grid, and the
    blocks form one compact group (each within 7 cm of another, whole group ≤ 17 cm across)."""

    name = "r031"
    description = ("Move all the blocks to the middle in a tidy little group. I don't want to be "
                   "reaching across the whole table.")

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _items(self, state):
        rel = relations(state)
        return [rel.in_bowl(b) is None and _cell(state, b) == "middle" for b in state.blocks]

    def _whole(self, state):
        bs = state.blocks
        if len(bs) < 2:
            return True
        xy = [_xy(state, b) for b in bs]
        if max(_dist(a, b) for a in xy for b in xy) > 0.17:
            return False
        return all(min(_dist(a, b) for j, b in enumerate(xy) if j != i) <= 0.07 for i, a in enumerate(xy))

    def _plan(self, state):
        region = _points(CX - 0.085, CX + 0.085, CY - 0.085, CY + 0.085, 0.01)
        anchors = _by_dist(region, (CX, CY))
        for anchor in anchors[::3][:60]:
            st, steps = state, []
            ok = True
            for b in _top_down(state, state.blocks):
                r = _put_first(st, b, _by_dist(region, anchor))
                if r is None:
                    ok = False
                    break
                st, step = r
                if not _noop_pair(state, st, b):
                    steps.append(step)
            if ok and self.satisfied(st):
                # drop moves that left a block where it was
                final = _simulate(state, steps)
                if final is not None and self.satisfied(final):
                    return steps
        return None


def _noop_pair(before: WorldState, after: WorldState, b: str) -> bool:
    return bool(np.allclose(before.positions[b], after.positions[b], atol=1e-6))


class R222(_Checker):
    """Reading: one tower of exactly three blocks (base resting on the table, not in a bowl) stands in
    the middle cell of the table; the other blocks may be anywhere."""

    name = "r222"
    description = ("A little chord in the middle of the table, please: three blocks stacked. "
                   "The others may stay where they are.")

    def feasible(self, scene):
        return len(scene.blocks) >= 3

    sample_kw = {"n_blocks": 3}

    def _tower_height(self, state, base):
        rel = relations(state)
        h, cur = 1, base
        while (a := rel.above(cur)) is not None and h < 10:
            h += 1
            cur = a
        return h

    def _items(self, state):
        rel = relations(state)
        best = 0
        for b in rel.on_table:
            if _cell(state, b) != "middle":
                continue
            h = self._tower_height(state, b)
            best = max(best, 3 if h == 3 else min(h, 2))
        return [i < best for i in range(3)]

    def _plan(self, state):
        middle = _by_dist(_points(CX - 0.08, CX + 0.08, CY - 0.08, CY + 0.08, 0.01), (CX, CY))
        rel = relations(state)
        in_mid = lambda p: table_position_name(p) == "middle"  # noqa: E731
        bases = sorted(
            state.blocks,
            key=lambda b: (not (b in rel.on_table and _cell(state, b) == "middle"), _dist(_xy(state, b), (CX, CY))),
        )
        for base in bases:
            steps: list[Skill] = []
            st = _clear(state, base, steps, ok=lambda p: not in_mid(p))
            if st is None:
                continue
            r2 = relations(st)
            if not (base in r2.on_table and _cell(st, base) == "middle"):
                r = _put_first(st, base, middle)
                if r is None:
                    continue
                st, s = r
                steps.append(s)
            top = base
            others = sorted((b for b in state.blocks if b != base), key=lambda b: _dist(_xy(st, b), _xy(st, base)))
            ok = True
            for b in others[:2]:
                st = _clear(st, b, steps, ok=lambda p: not in_mid(p))
                if st is None:
                    ok = False
                    break
                step = PutOn(block=b, target=top)
                new = _try(st, step)
                if new is None:
                    ok = False
                    break
                st = new
                steps.append(step)
                top = b
            if ok and self.satisfied(st):
                return steps
        return None


def _front_ok(state: WorldState, block: str, bowl: str) -> bool:
    rel = relations(state)
    if block not in rel.on_table:
        return False
    bx, by = _xy(state, bowl)
    x, y = _xy(state, block)
    return by - y >= 0.06 and abs(x - bx) <= 0.05 and rel.is_next_to(block, bowl)


def _place_with_blockers(state: WorldState, block: str, points: list[tuple[float, float]],
                         first: Skill | None, protect: set[str], park_ok=None):
    """Try ``first`` then PutAt points; if everything is taken, park blocks sitting near the ideal
    point (not those in ``protect``) and try again. Returns (state, steps) or None."""
    steps: list[Skill] = []
    st = _clear(state, block, steps, ok=park_ok)
    if st is None:
        return None
    for attempt in range(2):
        if first is not None:
            new = _try(st, first)
            if new is not None:
                return new, steps + [first]
        r = _put_first(st, block, points)
        if r is not None:
            return r[0], steps + [r[1]]
        if attempt == 1 or not points:
            break
        ideal = points[0]
        blockers = [
            b for b in st.blocks
            if b != block and b not in protect and _dist(_xy(st, b), ideal) < 0.06
        ]
        if not blockers:
            break
        for bl in _top_down(st, blockers):
            st = _clear(st, bl, steps, ok=park_ok)
            if st is None:
                return None
            r = _park(st, bl, lambda p: _dist(p, ideal) > 0.1 and (park_ok is None or park_ok(p)))
            if r is None:
                return None
            st, s = r
            steps.append(s)
    return None


class R036(_Checker):
    """Reading: for every colour that has both a block and a bowl, the block rests on the table just in
    front of (towards the front edge, i.e. smaller y) its bowl, roughly centred and touching-close;
    blocks without a partner bowl may stay anywhere."""

    name = "r036"
    description = ("Kindly put the blue block in front of the blue bowl, and the same for any other "
                   "colour that has a partner. Orderly, that's all I ask.")
    sample_kw = {"matching": True}

    def feasible(self, scene):
        return len(_matching_pairs(scene)) >= 1

    def _items(self, state):
        return [_front_ok(state, b, w) for b, w in _matching_pairs(state)]

    def _plan(self, state):
        st, steps = state, []
        pairs = _matching_pairs(state)
        done: set[str] = set()
        for b, w in pairs:
            if _front_ok(st, b, w):
                done.add(b)
                continue
            bx, by = _xy(st, w)
            pts = []
            for dy in (0.097, 0.105, 0.09, 0.115, 0.125):
                for dx in (0.0, 0.01, -0.01, 0.02, -0.02, 0.03, -0.03, 0.04, -0.04):
                    pts.append((round(bx + dx, 4), round(by - dy, 4)))
            pts = [p for p in pts if YMIN - 0.02 <= p[1] and XMIN - 0.02 <= p[0] <= XMAX + 0.02]
            r = _place_with_blockers(st, b, pts, PutNextTo(block=b, target=w, side="front"), done)
            if r is None:
                return None
            st, more = r
            steps += more
            done.add(b)
        return steps


class R206(_Checker):
    """Reading: when both the green and the red block exist, the green block sits directly on the red
    block; when either is missing nothing is to be done (any table is accepted)."""

    name = "r206"
    description = ("Green block on top of the red block: failing at the bottom, passing on top. "
                   "If either one is missing, do nothing at all.")

    def feasible(self, scene):
        return "green block" in scene.blocks and "red block" in scene.blocks

    def _items(self, state):
        if not ("green block" in state.positions and "red block" in state.positions):
            return [True]
        return [relations(state).below("green block") == "red block"]

    def _plan(self, state):
        if not ("green block" in state.positions and "red block" in state.positions):
            return []
        steps: list[Skill] = []
        st = _clear(state, "red block", steps)
        if st is None:
            return None
        st = _clear(st, "green block", steps)
        if st is None:
            return None
        step = PutOn(block="green block", target="red block")
        if _try(st, step) is None:
            return None
        return steps + [step]


def _corner_plan(state: WorldState, block: str, cell: str, corner_xy: tuple[float, float]):
    xlo, xhi = (X0, LEFT_LINE) if "left" in cell else (RIGHT_LINE, X1)
    ylo, yhi = (Y0, FRONT_LINE) if "bottom" in cell else (BACK_LINE, Y1)
    pts = _by_dist(_points(xlo + 0.02, xhi - 0.02, ylo + 0.02, yhi - 0.02, 0.01), corner_xy)
    in_cell = lambda p: table_position_name(p) == cell  # noqa: E731
    steps = _single_to_region(state, block, [corner_xy] + pts, in_cell)
    if steps is not None:
        return steps
    # fallback: on top of a block, or into a bowl, that is in that corner
    rel = relations(state)
    for w in state.bowls:
        if _cell(state, w) == cell and _dist(_xy(state, w), corner_xy) < 0.2:
            s = PutIn(block=block, bowl=w)
            if _try(state, s) is not None:
                return [s]
    for b in state.blocks:
        if b != block and _cell(state, b) == cell and rel.above(b) is None:
            s = PutOn(block=block, target=b)
            if _try(state, s) is not None:
                return [s]
    return None


class R060(_Checker):
    """Reading: the red block ends up in the front-left corner cell of the table (front = bottom side,
    x < -0.1, y < -0.6); other blocks may be anywhere."""

    name = "r060"
    description = ("Put the red block in the front left corner. Red is the first thing I want to see "
                   "when I walk in.")

    def feasible(self, scene):
        return "red block" in scene.blocks

    def _items(self, state):
        if "red block" not in state.positions:
            return [True]
        return [_cell(state, "red block") == "bottom left corner"]

    def _plan(self, state):
        if "red block" not in state.positions:
            return []
        return _corner_plan(state, "red block", "bottom left corner", (-0.25, -0.75))


# perceived lightness (CIE L*) of each colour, for "darker first"
def _lightness(color: str) -> float:
    def lin(c: float) -> float:
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = COLORS[color]
    y = 0.2126 * lin(r) + 0.7152 * lin(g) + 0.0722 * lin(b)
    return 116 * y ** (1 / 3) - 16 if y > 0.008856 else 903.3 * y


L_TIE = 2.5  # colours closer than this in L* count as equally dark (either order is fine)


class R032(_Checker):
    """Reading: going left to right, blocks get lighter (CIE lightness): every clearly darker block lies
    at least 3 cm further left than every clearly lighter one (near-equal pairs, blue/purple and
    red/green, may go either way); no particular row is required."""

    name = "r032"
    description = ("Sort them left to right by colour the way I'd read a ledger: the darker colours "
                   "first, the lighter ones after.")
    sample_kw = {"n_blocks": 3}

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def _items(self, state):
        bs = state.blocks
        out = []
        for a in bs:
            ok = True
            la, xa = _lightness(WorldState.color(a)), _xy(state, a)[0]
            for b in bs:
                if b == a:
                    continue
                lb, xb = _lightness(WorldState.color(b)), _xy(state, b)[0]
                if la < lb - L_TIE and not xa + 0.03 <= xb:
                    ok = False
                if lb < la - L_TIE and not xb + 0.03 <= xa:
                    ok = False
            out.append(ok)
        return out

    def _plan(self, state):
        ordered = sorted(state.blocks, key=lambda b: _lightness(WorldState.color(b)))
        my = float(np.mean([_xy(state, b)[1] for b in ordered]))
        ys = sorted(np.arange(-0.7, -0.299, 0.01), key=lambda y: abs(y - my))
        return _row_plan(state, ordered, ys, self.satisfied)


class R009(_Checker):
    """Reading: no block is inside (or stacked inside) any bowl; where they lie otherwise is free."""

    name = "r009"
    description = "No blocks in bowls please. The bowls are for snacks after school."

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def _items(self, state):
        rel = relations(state)
        return [rel.in_bowl(b) is None for b in state.blocks]

    def _plan(self, state):
        st, steps = state, []
        rel = relations(state)
        for b in _top_down(state, [b for b in state.blocks if rel.in_bowl(b)]):
            w = relations(st).in_bowl(b)
            if w is None:
                continue
            s = PutNextTo(block=b, target=w)
            new = _try(st, s)
            if new is None or relations(new).in_bowl(b):
                r = _park(st, b)
                if r is None:
                    return None
                new, s = r
            st = new
            steps.append(s)
        return steps


COMPLEMENTS = [("orange block", "blue block"), ("red block", "green block"), ("yellow block", "purple block")]


class R077(_Checker):
    """Reading: for each complementary pair of blocks present (orange/blue, red/green, yellow/purple)
    the first sits directly on the second; every other block rests on the table in one straight row
    (same y ± 1.5 cm) in the back third of the table (y > -0.4)."""

    name = "r077"
    description = ("Complementary pairs, if they exist: put the orange on the blue, the red on the "
                   "green, the yellow on the purple. Leftovers just sit in a row at the back.")

    def feasible(self, scene):
        return any(u in scene.blocks and l in scene.blocks for u, l in COMPLEMENTS)

    def _pairs(self, state):
        return [(u, l) for u, l in COMPLEMENTS if u in state.positions and l in state.positions]

    def _leftovers(self, state):
        used = {b for p in self._pairs(state) for b in p}
        return [b for b in state.blocks if b not in used]

    def _items(self, state):
        rel = relations(state)
        items = [rel.below(u) == l for u, l in self._pairs(state)]
        left = self._leftovers(state)
        row = _is_row(state, left)
        items += [ok and _xy(state, b)[1] > BACK_LINE for b, ok in zip(left, row)]
        return items

    def _plan(self, state):
        steps: list[Skill] = []
        pairs = self._pairs(state)

        def bad(st, rel, b):
            lo = rel.below(b)
            return lo is not None and not ((b, lo) in pairs and rel.below(lo) is None)

        st = _flatten(state, steps, bad)
        if st is None:
            return None
        for u, l in pairs:
            if relations(st).below(u) == l:
                continue
            st = _clear(st, l, steps)
            if st is None:
                return None
            st = _clear(st, u, steps)
            if st is None:
                return None
            s = PutOn(block=u, target=l)
            st = _try(st, s)
            if st is None:
                return None
            steps.append(s)
        left = sorted(self._leftovers(state), key=lambda b: _xy(st, b)[0])
        ys = np.arange(YMAX, BACK_LINE + 0.015 - 1e-9, -0.01)
        rest = _row_plan(st, left, ys, self.satisfied, ref_x=float(np.mean([_xy(st, b)[0] for b in left])) if left else 0.0)
        if rest is None:
            return None
        return steps + rest


class R133(_Checker):
    """Reading: only when blue, red and green blocks all exist: all three rest on the table in a short
    left-to-right line blue, red, green, blue and green each right beside the red (3–10 cm, same y
    ± 3 cm); if one is missing nothing is asked."""

    name = "r133"
    description = ("Put the blue block to the left of the red one and the green block to the right of "
                   "it, like a little traffic light sideways. If one of those is missing, never mind.")
    NAMES = ("blue block", "red block", "green block")

    def feasible(self, scene):
        return all(n in scene.blocks for n in self.NAMES)

    def _items(self, state):
        if not all(n in state.positions for n in self.NAMES):
            return [True]
        rel = relations(state)
        (bx, by), (rx, ry), (gx, gy) = (_xy(state, n) for n in self.NAMES)
        on = [n in rel.on_table for n in self.NAMES]
        left = on[0] and 0.03 <= rx - bx <= 0.10 and abs(by - ry) <= 0.03
        right = on[2] and 0.03 <= gx - rx <= 0.10 and abs(gy - ry) <= 0.03
        return [left, on[1], right]

    def _attempt(self, st):
        r = _execute(st, [
            PutNextTo(block="blue block", target="red block", side="left"),
            PutNextTo(block="green block", target="red block", side="right"),
        ])
        if r is not None and self.satisfied(r[0]):
            return r[1]
        return None

    def _plan(self, state):
        if not all(n in state.positions for n in self.NAMES):
            return []
        steps: list[Skill] = []
        st = state
        for n in self.NAMES:
            st = _clear(st, n, steps)
            if st is None:
                return None
        if "red block" in relations(st).on_table:
            r = self._attempt(st)
            if r is not None:
                return steps + r
        here = _xy(st, "red block")
        for p in _by_dist(_points(XMIN + 0.05, XMAX - 0.05, YMIN, YMAX, 0.02), here):
            s = PutAt(block="red block", position=p)
            new = _try(st, s)
            if new is None:
                continue
            r = self._attempt(new)
            if r is not None:
                return steps + [s] + r
        return None


HUE_ORDER = ["red", "orange", "yellow", "green", "cyan", "blue", "purple", "pink", "brown", "gray"]
HUE_RANK = {c: i for i, c in enumerate(HUE_ORDER)}
HUE_RANK["gray"] = HUE_RANK["brown"]  # "brown and gray at the very end": either order


class R044(_Checker):
    """Reading: all blocks rest on the table in one straight left-to-right line (same y ± 1.5 cm) in
    the order red, orange, yellow, green, cyan, blue, purple, pink, then brown and gray (those two in
    either order)."""

    name = "r044"
    description = ("Arrange the blocks in a line from left to right sorted by hue, like a colour wheel: "
                   "red, orange, yellow, green, cyan, blue, purple, pink. Brown and gray at the very end.")
    sample_kw = {"n_blocks": 3}

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def _items(self, state):
        bs = state.blocks
        row = _is_row(state, bs)
        out = []
        for a, in_row in zip(bs, row):
            ok = in_row
            ra, xa = HUE_RANK[WorldState.color(a)], _xy(state, a)[0]
            for b in bs:
                if b == a:
                    continue
                rb, xb = HUE_RANK[WorldState.color(b)], _xy(state, b)[0]
                if ra < rb and not xa + 0.03 <= xb:
                    ok = False
                if rb < ra and not xb + 0.03 <= xa:
                    ok = False
            out.append(ok)
        return out

    def _plan(self, state):
        ordered = sorted(state.blocks, key=lambda b: HUE_ORDER.index(WorldState.color(b)))
        my = float(np.mean([_xy(state, b)[1] for b in ordered]))
        ys = sorted(np.arange(-0.7, -0.299, 0.01), key=lambda y: abs(y - my))
        return _row_plan(state, ordered, ys, self.satisfied)


class R318(_Checker):
    """Reading: if there is a yellow block, it ends up in the top-right (back-right) corner cell of the
    table (x > 0.1, y > -0.4); without one nothing is asked."""

    name = "r318"
    description = ("If there's a yellow block put it in the top right corner, that's my priority marker "
                   "for the day.")

    def feasible(self, scene):
        return "yellow block" in scene.blocks

    def _items(self, state):
        if "yellow block" not in state.positions:
            return [True]
        return [_cell(state, "yellow block") == "top right corner"]

    def _plan(self, state):
        if "yellow block" not in state.positions:
            return []
        return _corner_plan(state, "yellow block", "top right corner", (0.25, -0.25))


class R186(_Checker):
    """Reading: every block is inside some bowl (any bowl, stacking inside a bowl is fine)."""

    name = "r186"
    description = "No block left lying loose. Everything in a bowl, I don't care which one."

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def _items(self, state):
        rel = relations(state)
        return [rel.in_bowl(b) is not None for b in state.blocks]

    def _plan(self, state):
        return _all_in_bowl_plan(state, _nearest_bowl)


class R260(R186):
    """Reading: every block is inside some bowl (any bowl, stacking inside a bowl is fine)."""

    name = "r260"
    description = "Clean bench by the end of the day: every block in a bowl. Which bowl doesn't matter."


class R005(_Checker):
    """Reading: no block lies in any of the four corner cells of the 3×3 table grid (bowls cannot be
    moved and are ignored)."""

    name = "r005"
    description = "Keep everything away from the corners, the little one bangs her elbows on that table."

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _items(self, state):
        return [_cell(state, b) not in CORNER_CELLS for b in state.blocks]

    def _plan(self, state):
        allowed = [
            p for p in _points(XMIN, XMAX, YMIN, YMAX, 0.01)
            if abs(p[0] - CX) <= THIRD_X / 2 - 0.03 or abs(p[1] - CY) <= THIRD_Y / 2 - 0.03
        ]
        movers = [b for b in state.blocks if _cell(state, b) in CORNER_CELLS]
        return _blocks_to_region(state, movers, lambda st, b: _by_dist(allowed, _xy(st, b)))


class R308(_Checker):
    """Reading: every block whose colour has a bowl rests on the table right next to that bowl (the
    world's next-to relation); other blocks may be anywhere; only out-of-place blocks are moved."""

    name = "r308"
    description = ("Minimise moves. If a block's already next to its matching bowl, leave it; only move "
                   "what's out of place.")
    sample_kw = {"matching": True}

    def feasible(self, scene):
        return len(_matching_pairs(scene)) >= 1

    def _items(self, state):
        rel = relations(state)
        return [rel.is_next_to(b, w) for b, w in _matching_pairs(state)]

    def _plan(self, state):
        st, steps = state, []
        done: set[str] = set()
        for b, w in _matching_pairs(state):
            if relations(st).is_next_to(b, w):
                done.add(b)
                continue
            pts = _ring_pts(_xy(st, w), _xy(st, b))
            r = _place_with_blockers(st, b, pts, PutNextTo(block=b, target=w), done)
            if r is None:
                return None
            new, more = r
            if not relations(new).is_next_to(b, w):
                return None
            st = new
            steps += more
            done.add(b)
        return steps


class R241(_Checker):
    """Reading: every block ends up in the bottom-right (front-right) corner cell (x > 0.1, y < -0.6),
    packed towards the corner; stacking or a bowl in that corner is fine; bowls themselves stay."""

    name = "r241"
    description = ("asymmetric please. push everything into the bottom right corner and leave the rest "
                   "of the table empty. negative space is a thing")

    CELL = "bottom right corner"

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _items(self, state):
        return [_cell(state, b) == self.CELL for b in state.blocks]

    def _plan(self, state):
        pts = _points(RIGHT_LINE + 0.025, X1, Y0, FRONT_LINE - 0.025, 0.01)
        pts = _by_dist(pts, (X1, Y0))
        movers = [b for b in state.blocks if _cell(state, b) != self.CELL]

        def fallback(st, b):
            rel = relations(st)
            out: list[Skill] = []
            for w in st.bowls:
                if _cell(st, w) == self.CELL:
                    out.append(PutIn(block=b, bowl=w))
            for o in st.blocks:
                if o != b and _cell(st, o) == self.CELL and rel.above(o) is None:
                    out.append(PutOn(block=b, target=o))
            return out

        return _blocks_to_region(state, movers, lambda st, b: pts, fallback)


class R293(_Checker):
    """Reading: no block lies (even partly) in the front half of the table: every block centre is at
    least half a block behind the front/back midline (y ≥ -0.48)."""

    name = "r293"
    description = "Keep the front half of the table clear. That's where I put my tea and my book."
    LIMIT = CY + HALF

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _items(self, state):
        return [_xy(state, b)[1] >= self.LIMIT - 1e-9 for b in state.blocks]

    def _plan(self, state):
        allowed = _points(XMIN, XMAX, self.LIMIT + 0.01, YMAX, 0.01)
        movers = [b for b in state.blocks if _xy(state, b)[1] < self.LIMIT - 1e-9]
        return _blocks_to_region(state, movers, lambda st, b: _by_dist(allowed, _xy(st, b)))


class R142(_Checker):
    """Reading: bowls taken left to right get two blocks each until blocks run out (so bowl i holds
    min(2, blocks left) blocks); any blocks beyond two per bowl rest outside bowls in the right third of
    the table (x > 0.1)."""

    name = "r142"
    description = ("Two blocks per bowl, no more. Fill the bowls from left to right and leave anything "
                   "extra along the right side.")
    sample_kw = {"n_blocks": 3}

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def _need(self, state):
        bowls = sorted(state.bowls, key=lambda w: _xy(state, w)[0])
        n = len(state.blocks)
        return bowls, [min(2, max(0, n - 2 * i)) for i in range(len(bowls))]

    def _items(self, state):
        rel = relations(state)
        bowls, need = self._need(state)
        items = []
        for w, k in zip(bowls, need):
            items.append(sum(1 for b in state.blocks if rel.in_bowl(b) == w) == k)
        n_extra = max(0, len(state.blocks) - 2 * len(bowls))
        loose = [b for b in state.blocks if rel.in_bowl(b) is None]
        items += [_xy(state, b)[0] > RIGHT_LINE for b in loose]
        if len(loose) != n_extra:
            items.append(False)
        return items

    def _plan(self, state):
        pre: list[Skill] = []
        state = _flatten(state, pre, _on_loose_block)
        if state is None:
            return None
        r = self._plan_flat(state)
        return None if r is None else pre + r

    def _plan_flat(self, state):
        rel = relations(state)
        bowls, need = self._need(state)
        inside = {w: sorted((b for b in state.blocks if rel.in_bowl(b) == w), key=lambda b: _z(state, b)) for w in bowls}
        pool = [b for b in state.blocks if rel.in_bowl(b) is None]
        for w, k in zip(bowls, need):
            pool += inside[w][k:]
            inside[w] = inside[w][:k]
        fills: list[Skill] = []
        for w, k in zip(bowls, need):
            for _ in range(k - len(inside[w])):
                b = min(pool, key=lambda b: (_xy(state, b)[0] > RIGHT_LINE and rel.in_bowl(b) is None,
                                              _dist(_xy(state, b), _xy(state, w))))
                pool.remove(b)
                fills.append(PutIn(block=b, bowl=w))
        # extras: those already loose on the right stay; others go to the right third
        st, steps = state, []
        right_pts = _points(RIGHT_LINE + 0.03, XMAX, YMIN, YMAX, 0.01)
        movers = [b for b in pool if not (rel.in_bowl(b) is None and _xy(state, b)[0] > RIGHT_LINE)]
        for b in _top_down(state, movers):
            here = _xy(st, b)
            r = _put_first(st, b, sorted(right_pts, key=lambda p: (abs(p[0] - 0.25) + 0.5 * abs(p[1] - here[1]), p)))
            if r is None:
                return None
            st, s = r
            steps.append(s)
        r = _execute(st, fills)
        if r is None:
            return None
        return steps + r[1]


class R282(_Checker):
    """Reading: each bowl holds at most one block and as many bowls as possible get one; the extra
    blocks form a single stack (one block alone if only one) resting on the table in the back-right
    corner cell (x > 0.1, y > -0.4)."""

    name = "r282"
    description = ("Each bowl should get one block, no more. If there are extra blocks, stack them in "
                   "the back right corner.")
    sample_kw = {"n_blocks": 3}
    CELL = "top right corner"

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def _items(self, state):
        rel = relations(state)
        items = []
        for w in state.bowls:
            items.append(sum(1 for b in state.blocks if rel.in_bowl(b) == w) <= 1)
        n_in = sum(1 for b in state.blocks if rel.in_bowl(b) is not None)
        items.append(n_in == min(len(state.blocks), len(state.bowls)))
        extras = [b for b in state.blocks if rel.in_bowl(b) is None]
        bases = [b for b in extras if b in rel.on_table]
        for b in extras:
            ok = _cell(state, b) == self.CELL and (b in rel.on_table or rel.below(b) in extras)
            items.append(ok)
        if extras and len(bases) != 1:
            items.append(False)
        return items

    def _plan(self, state):
        pre: list[Skill] = []
        state = _flatten(state, pre, _on_loose_block)
        if state is None:
            return None
        r = self._plan_flat(state)
        return None if r is None else pre + r

    def _plan_flat(self, state):
        rel = relations(state)
        bowls = list(state.bowls)
        keep = {}
        pool = []
        for w in bowls:
            ins = sorted((b for b in state.blocks if rel.in_bowl(b) == w), key=lambda b: _z(state, b))
            if ins:
                keep[w] = ins[0]
                pool += ins[1:]
        pool += [b for b in state.blocks if rel.in_bowl(b) is None]
        fills: list[Skill] = []
        for w in bowls:
            if w in keep or not pool:
                continue
            same = [b for b in pool if WorldState.color(b) == WorldState.color(w)]
            b = same[0] if same else min(pool, key=lambda b: _dist(_xy(state, b), _xy(state, w)))
            pool.remove(b)
            fills.append(PutIn(block=b, bowl=w))
        extras = pool
        st, steps = state, []
        if extras:
            cell_pts = _by_dist(_points(RIGHT_LINE + 0.025, X1, BACK_LINE + 0.025, Y1, 0.01), (0.25, -0.25))
            # base: an extra already resting alone in the corner, else the one nearest the corner
            cands = sorted(extras, key=lambda b: (not (b in rel.on_table and _cell(state, b) == self.CELL),
                                                  _dist(_xy(state, b), (0.25, -0.25))))
            base = None
            for c in cands:
                tmp: list[Skill] = []
                s2 = _clear(st, c, tmp, ok=lambda p: table_position_name(p) != self.CELL)
                if s2 is None:
                    continue
                if c in relations(s2).on_table and _cell(s2, c) == self.CELL:
                    st, base = s2, c
                    steps += tmp
                    break
                r = _put_first(s2, c, cell_pts)
                if r is not None:
                    st, base = r[0], c
                    steps += tmp + [r[1]]
                    break
            if base is None:
                return None
            top = base
            rest = [b for b in extras if b != base]
            while rest:
                for b in _top_down(st, rest):
                    s = PutOn(block=b, target=top)
                    new = _try(st, s)
                    if new is not None:
                        st = new
                        steps.append(s)
                        rest.remove(b)
                        top = b
                        break
                else:
                    return None
        r = _execute(st, fills)
        if r is None:
            return None
        return steps + r[1]


class R021(_Checker):
    """Reading: all blocks rest on the table (not in bowls, not stacked) in one straight left-to-right
    row (same y ± 1.5 cm) in the back third of the table (y > -0.4), neighbours at most 25 cm apart."""

    name = "r021"
    description = ("I'd like all the blocks in a neat row along the back of the table, and nothing left "
                   "lying loose in the middle.")

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _items(self, state):
        bs = state.blocks
        row = _is_row(state, bs)
        return [ok and _xy(state, b)[1] > BACK_LINE for b, ok in zip(bs, row)]

    def _whole(self, state):
        xs = sorted(_xy(state, b)[0] for b in state.blocks)
        return all(b - a <= 0.25 for a, b in zip(xs, xs[1:]))

    def _plan(self, state):
        ordered = sorted(state.blocks, key=lambda b: _xy(state, b)[0])
        ys = np.arange(YMAX, BACK_LINE + 0.015 - 1e-9, -0.01)
        return _row_plan(state, ordered, ys, self.satisfied,
                         ref_x=float(np.mean([_xy(state, b)[0] for b in ordered])))


class R058(_Checker):
    """Reading: no block (loose or in a bowl) has its centre in the middle cell of the 3×3 table grid."""

    name = "r058"
    description = "Nothing left loose in the middle. Middle is the walkway, keep it clear."

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _items(self, state):
        return [_cell(state, b) != "middle" for b in state.blocks]

    def _plan(self, state):
        allowed = [
            p for p in _points(XMIN, XMAX, YMIN, YMAX, 0.01)
            if abs(p[0] - CX) >= THIRD_X / 2 + 0.03 or abs(p[1] - CY) >= THIRD_Y / 2 + 0.03
        ]
        movers = [b for b in state.blocks if _cell(state, b) == "middle"]
        return _blocks_to_region(state, movers, lambda st, b: _by_dist(allowed, _xy(st, b)))


class R355(_Checker):
    """Reading: if there is a green bowl, the green block (if any) is inside it and every other block
    rests on the table right next to the green bowl (world next-to relation), in no bowl; without a
    green bowl nothing is asked."""

    name = "r355"
    description = ("If there's a green bowl, the green block goes in it and the others stay out around "
                   "it. Like a pincushion.")

    def feasible(self, scene):
        return "green bowl" in scene.bowls and "green block" in scene.blocks

    def _items(self, state):
        if "green bowl" not in state.positions:
            return [True for _ in state.blocks]
        rel = relations(state)
        out = []
        for b in state.blocks:
            if b == "green block":
                out.append(rel.in_bowl(b) == "green bowl")
            else:
                out.append(rel.in_bowl(b) is None and rel.is_next_to(b, "green bowl"))
        return out

    def _plan(self, state):
        if "green bowl" not in state.positions:
            return []
        rel = relations(state)
        st, steps = state, []
        others = [b for b in state.blocks if b != "green block"]
        # first take other blocks out of the green bowl (top first)
        bad = [b for b in others if not (rel.in_bowl(b) is None and rel.is_next_to(b, "green bowl"))]
        done = [b for b in others if b not in bad]
        center = _xy(state, "green bowl")
        for b in _top_down(state, bad):
            pts = _ring_pts(center, _xy(st, b))
            r = _place_with_blockers(st, b, pts, None, set(done) | {"green block"})
            if r is None:
                return None
            new, more = r
            if not relations(new).is_next_to(b, "green bowl"):
                return None
            st = new
            steps += more
            done.append(b)
        if "green block" in st.positions and relations(st).in_bowl("green block") != "green bowl":
            st = _clear(st, "green block", steps)
            if st is None:
                return None
            s = PutIn(block="green block", bowl="green bowl")
            if _try(st, s) is None:
                return None
            steps.append(s)
        return steps


def _own_bowl(state: WorldState, b: str) -> str | None:
    w = f"{WorldState.color(b)} bowl"
    return w if w in state.positions else None


def _flat_and_fill(state: WorldState):
    """Undo stacks and blocks in wrong bowls (parking them on the table), then put every block that
    has a same-coloured bowl into it. Returns (state, steps) or None."""
    steps: list[Skill] = []

    def bad(st, rel, b):
        w = rel.in_bowl(b)
        return rel.below(b) is not None or (w is not None and w != _own_bowl(st, b))

    st = _flatten(state, steps, bad)
    if st is None:
        return None
    rel = relations(st)
    fills = [PutIn(block=b, bowl=w) for b, w in _matching_pairs(st) if rel.in_bowl(b) != w]
    r = _execute(st, fills)
    if r is None:
        return None
    return r[0], steps + r[1]


class R262(_Checker):
    """Reading: blocks with a same-coloured bowl are inside it; all other blocks rest outside bowls in
    the back-left corner cell (x < -0.1, y > -0.4), stacked in towers of at most two, as few towers as
    that allows (ceil(n/2))."""

    name = "r262"
    description = ("If a block has a bowl of its colour, in it goes. The rest stack in the back left "
                   "corner, two high at most.")
    sample_kw = {"n_blocks": 3, "matching": True}
    CELL = "top left corner"

    def feasible(self, scene):
        return len(scene.blocks) >= 1

    def _rest(self, state):
        return [b for b in state.blocks if f"{WorldState.color(b)} bowl" not in state.positions]

    def _items(self, state):
        rel = relations(state)
        items = [rel.in_bowl(b) == w for b, w in _matching_pairs(state)]
        rest = self._rest(state)
        for b in rest:
            below = rel.below(b)
            ok = rel.in_bowl(b) is None and _cell(state, b) == self.CELL
            ok = ok and (b in rel.on_table or (below in rest and below in rel.on_table))
            items.append(ok)
        if rest:
            bases = sum(1 for b in rest if b in rel.on_table)
            items.append(bases == math.ceil(len(rest) / 2))
        return items

    def _plan(self, state):
        r = _flat_and_fill(state)
        if r is None:
            return None
        st, steps = r
        rest = self._rest(st)
        corner = (-0.25, -0.25)
        pts = _by_dist(_points(X0, LEFT_LINE - 0.025, BACK_LINE + 0.025, Y1, 0.01), corner)
        order = sorted(rest, key=lambda b: _dist(_xy(st, b), corner))
        for i in range(0, len(order), 2):
            grp = order[i:i + 2]
            base = grp[0]
            r = _put_first(st, base, pts)
            if r is None:
                return None
            st, s = r
            steps.append(s)
            if len(grp) == 2:
                s = PutOn(block=grp[1], target=base)
                st = _try(st, s)
                if st is None:
                    return None
                steps.append(s)
        return steps


class R263(_Checker):
    """Reading: the brown block rests on the table right next to the brown bowl on its right-hand side
    (at least 6 cm right of the bowl centre, within 5 cm in y, next-to relation holds)."""

    name = "r263"
    description = "Brown block next to the brown bowl, on its right. Brown's for Biscuit and Pepper."

    def feasible(self, scene):
        return "brown block" in scene.blocks and "brown bowl" in scene.bowls

    def _items(self, state):
        if not ("brown block" in state.positions and "brown bowl" in state.positions):
            return [True]
        rel = relations(state)
        (x, y), (bx, by) = _xy(state, "brown block"), _xy(state, "brown bowl")
        return [rel.is_next_to("brown block", "brown bowl") and x - bx >= 0.06 and abs(y - by) <= 0.05]

    def _plan(self, state):
        if not ("brown block" in state.positions and "brown bowl" in state.positions):
            return []
        bx, by = _xy(state, "brown bowl")
        pts = []
        for dx in (0.097, 0.105, 0.09, 0.115, 0.125):
            for dy in (0.0, 0.01, -0.01, 0.02, -0.02, 0.03, -0.03, 0.04, -0.04):
                pts.append((round(bx + dx, 4), round(by + dy, 4)))
        r = _place_with_blockers(state, "brown block", pts,
                                 PutNextTo(block="brown block", target="brown bowl", side="right"), set())
        return None if r is None else r[1]


class R181(_Checker):
    """Reading: blocks with a same-coloured bowl are inside it; the other blocks rest on the table in
    one straight row (same y ± 1.5 cm) along the front edge (centres within 10 cm of it, y ≤ -0.70)."""

    name = "r181"
    description = ("Put every block in the bowl that matches its colour. If there's no matching bowl, "
                   "line it up along the front edge like stock on a shelf.")
    sample_kw = {"n_blocks": 3, "matching": True}
    FRONT = Y0 + 0.10

    def feasible(self, scene):
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def _rest(self, state):
        return [b for b in state.blocks if f"{WorldState.color(b)} bowl" not in state.positions]

    def _items(self, state):
        rel = relations(state)
        items = [rel.in_bowl(b) == w for b, w in _matching_pairs(state)]
        rest = self._rest(state)
        items += [ok and _xy(state, b)[1] <= self.FRONT + 1e-9 for b, ok in zip(rest, _is_row(state, rest))]
        return items

    def _plan(self, state):
        r = _flat_and_fill(state)
        if r is None:
            return None
        st, steps = r
        rest = sorted(self._rest(st), key=lambda b: _xy(st, b)[0])
        ys = np.arange(YMIN, self.FRONT + 1e-9, 0.005)
        ref = float(np.mean([_xy(st, b)[0] for b in rest])) if rest else 0.0
        row = _row_plan(st, rest, ys, self.satisfied, ref_x=ref)
        return None if row is None else steps + row


class R298(_Checker):
    """Reading: the gray block is inside the gray bowl (when both exist); other blocks are free."""

    name = "r298"
    description = "Gray block in the gray bowl, always. It's the one I notice first if it's wrong."

    def feasible(self, scene):
        return "gray block" in scene.blocks and "gray bowl" in scene.bowls

    def _items(self, state):
        if not ("gray block" in state.positions and "gray bowl" in state.positions):
            return [True]
        return [relations(state).in_bowl("gray block") == "gray bowl"]

    def _plan(self, state):
        if not ("gray block" in state.positions and "gray bowl" in state.positions):
            return []
        steps: list[Skill] = []
        st = _clear(state, "gray block", steps)
        if st is None:
            return None
        s = PutIn(block="gray block", bowl="gray bowl")
        if _try(st, s) is None:
            return None
        return steps + [s]


class R288(_Checker):
    """Reading: every block is out of the bowls and further back than all bowls: its centre lies behind
    the back rim of the back-most bowl (y ≥ that bowl's y + 6.5 cm; behind = towards the back edge)."""

    name = "r288"
    description = ("Make sure the blocks are all behind the bowls, so the bowls kind of act like a "
                   "little fence.")
    MARGIN = BOWL_RADIUS

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def _line(self, state):
        return max(_xy(state, w)[1] for w in state.bowls) + self.MARGIN

    def _items(self, state):
        if not state.bowls:
            return [True for _ in state.blocks]
        rel = relations(state)
        line = self._line(state)
        return [rel.in_bowl(b) is None and _xy(state, b)[1] >= line - 1e-9 for b in state.blocks]

    def _plan(self, state):
        line = self._line(state)
        rel = relations(state)
        allowed = [
            (round(float(x), 4), round(float(y), 4))
            for x in np.arange(XMIN, XMAX + 1e-9, 0.005)
            for y in np.arange(min(line + 0.005, Y1 - HALF), Y1 - HALF + 1e-9, 0.005)
        ]
        movers = [b for b in state.blocks if not (rel.in_bowl(b) is None and _xy(state, b)[1] >= line - 1e-9)]
        return _blocks_to_region(state, movers, lambda st, b: _by_dist(allowed, _xy(st, b)))


ALL_CHECKERS = [
    R326, R031, R222, R036, R206, R060, R032, R009, R077, R133, R044, R318, R186, R260,
    R005, R308, R241, R293, R142, R282, R021, R058, R355, R262, R263, R181, R298, R288,
]
