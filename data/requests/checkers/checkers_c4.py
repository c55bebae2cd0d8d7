"""Checkers for requests r050, r082, r110, r158, r208, r253, r277, r017, r123, r204, r248, r329.

Each class judges a final table (``satisfied`` / ``score``), says whether the request can be
shown in a scene (``feasible``), samples such scenes and plans a way to a satisfying table
under the symbolic world model (``activeintent.world.apply_skill``).

Conventions used throughout: the table is x in [-0.3, 0.3] (left -> right), y in [-0.8, -0.2]
(front -> back); regions such as "corner", "back", "front middle" are the cells of the 3 x 3
Code-as-Policies grid (``table_position_name``).  A block "in a bowl" is one whose centre lies
within the bowl's inner radius (as ``relations`` decides); a block "on the table" rests on the
table top (not in a bowl, not on another block).
"""

from __future__ import annotations

import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOWL_RADIUS,
    COLOR_NAMES,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    WorldState,
    apply_plan,
    apply_skill,
    relations,
    sample_scene,
    table_position_name,
)

Z_TABLE = BLOCK_SIZE / 2  # centre height of a block resting on the table
Z_TOL = 0.012  # settling tolerance on heights
CENTRE = (0.0, -0.5)

# ----------------------------------------------------------------------------------------
# geometry helpers
# ----------------------------------------------------------------------------------------

_COLS = {"left": (-0.3, -0.1), "center": (-0.1, 0.1), "right": (0.1, 0.3)}
_ROWS = {"top": (-0.4, -0.2), "middle": (-0.6, -0.4), "bottom": (-0.8, -0.6)}
_CELLS = {
    "top left corner": ("top", "left"),
    "top side": ("top", "center"),
    "top right corner": ("top", "right"),
    "left side": ("middle", "left"),
    "middle": ("middle", "center"),
    "right side": ("middle", "right"),
    "bottom left corner": ("bottom", "left"),
    "bottom side": ("bottom", "center"),
    "bottom right corner": ("bottom", "right"),
}
CORNERS = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")
NON_CORNERS = tuple(c for c in _CELLS if c not in CORNERS)


def _kind(name: str) -> str:
    return name.rsplit(" ", 1)[-1]


def _color(name: str) -> str:
    return name.split(" ", 1)[0]


def _xy(state: WorldState, name: str) -> tuple[float, float]:
    p = state.positions[name]
    return float(p[0]), float(p[1])


def _z(state: WorldState, name: str) -> float:
    return float(state.positions[name][2])


def _dist(a, b) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _cell(state: WorldState, name: str) -> str:
    return table_position_name(_xy(state, name))


SLACK = 0.01  # settling noise: a block this close to a region counts as in it when judging
_OFFSETS = [(dx, dy) for dx in (0, -1, 1) for dy in (0, -1, 1)]


def _in_region(xy, cells, slack: float = 0.0) -> bool:
    """The point lies in one of the grid cells, or within ``slack`` of one."""
    return any(
        table_position_name((xy[0] + dx * slack, xy[1] + dy * slack)) in cells for dx, dy in _OFFSETS
    )


def _in_cell(x: float, y: float, cell: str, margin: float = 0.0) -> bool:
    """(x, y) lies in the grid cell, at least ``margin`` inside its borders."""
    r, c = _CELLS[cell]
    (x0, x1), (y0, y1) = _COLS[c], _ROWS[r]
    return x0 + margin <= x <= x1 - margin and y0 + margin <= y <= y1 - margin


def _in_bowl(state: WorldState, b: str) -> str | None:
    return relations(state).in_bowl(b)


def _on_table(state: WorldState, b: str) -> bool:
    """Resting on the table top: not in a bowl, not on another block."""
    return _in_bowl(state, b) is None and abs(_z(state, b) - Z_TABLE) <= Z_TOL


def _chain_up(state: WorldState, b: str) -> list[str]:
    """b and the blocks stacked on it, bottom to top."""
    rel = relations(state)
    out = [b]
    seen = {b}
    t = rel.above(b)
    while t is not None and t not in seen:
        out.append(t)
        seen.add(t)
        t = rel.above(t)
    return out


def _base_of(state: WorldState, b: str) -> str:
    rel = relations(state)
    seen = {b}
    while (d := rel.below(b)) is not None and d not in seen:
        seen.add(d)
        b = d
    return b


def _towers(state: WorldState) -> list[list[str]]:
    """Every stack of blocks (a single block is a stack of one), bottom to top."""
    rel = relations(state)
    return [_chain_up(state, b) for b in state.blocks if rel.below(b) is None]


def _single_tower(state: WorldState, blocks: list[str]) -> list[str] | None:
    """The tower (bottom to top) if ``blocks`` are exactly one stack, else None."""
    if not blocks:
        return []
    rel = relations(state)
    bases = [b for b in blocks if rel.below(b) is None or rel.below(b) not in blocks]
    if len(bases) != 1:
        return None
    chain = _chain_up(state, bases[0])
    if len(chain) != len(blocks) or set(chain) != set(blocks):
        return None
    return chain


def _nearest_bowl(state: WorldState, b: str, exclude: set[str] = frozenset()) -> str | None:
    """The bowl of the block's colour if there is one, else the nearest bowl."""
    bowls = [w for w in state.bowls if w not in exclude] or list(state.bowls)
    if not bowls:
        return None
    same = f"{_color(b)} bowl"
    if same in bowls:
        return same
    return min(bowls, key=lambda w: _dist(_xy(state, w), _xy(state, b)))


def _score(ok: int, n: int, sat: bool) -> float:
    if sat:
        return 1.0
    if n == 0:
        return 0.0
    return float(min(ok / n, 1.0 - 0.5 / n))


def _scene_with(rng: np.random.Generator, blocks: list[str], bowls: list[str], n_blocks: int, n_bowls: int) -> Scene:
    """A scene holding the given block and bowl colours plus random others, to the counts."""
    blocks = list(blocks)
    bowls = list(bowls)
    free = [c for c in COLOR_NAMES if c not in blocks]
    extra = list(rng.choice(free, size=max(0, n_blocks - len(blocks)), replace=False)) if n_blocks > len(blocks) else []
    blocks += [str(c) for c in extra]
    free = [c for c in COLOR_NAMES if c not in bowls]
    extra = list(rng.choice(free, size=max(0, n_bowls - len(bowls)), replace=False)) if n_bowls > len(bowls) else []
    bowls += [str(c) for c in extra]
    return Scene(objects=[f"{c} block" for c in blocks] + [f"{c} bowl" for c in bowls])


# ----------------------------------------------------------------------------------------
# planning helpers (a small simulator over the symbolic world model)
# ----------------------------------------------------------------------------------------

_GX = [round(v, 3) for v in np.arange(-0.28, 0.28001, 0.01)]
_GY = [round(v, 3) for v in np.arange(-0.78, -0.21999, 0.01)]


class _Fail(Exception):
    pass


class _Base(Intention):
    """``satisfied`` judges with a centimetre of slack at region borders; planners aim at
    ``strict`` (no slack) and keep moved blocks well inside regions, so that settling noise
    never turns a planned table into a rejected one."""

    def _sat(self, state: WorldState, slack: float) -> bool:
        raise NotImplementedError

    def satisfied(self, state: WorldState) -> bool:
        return self._sat(state, SLACK)

    def strict(self, state: WorldState) -> bool:
        return self._sat(state, 0.0)


def _free_xy(state: WorldState, xy, moving: str | None, extra: float = 0.006, ignore=()) -> bool:
    """A block could be put at xy (as world.predict checks it), with ``extra`` clearance."""
    for o, p in state.positions.items():
        if o == moving or o in ignore:
            continue
        if _kind(o) == "block" and p[2] > BLOCK_SIZE:  # stacked: its base is checked
            continue
        r = BOWL_RADIUS if _kind(o) == "bowl" else BLOCK_SIZE / 2
        if math.hypot(p[0] - xy[0], p[1] - xy[1]) < r + BLOCK_SIZE / 2 + 0.004 + extra:
            return False
    return True


def _find_spot(state: WorldState, moving: str | None, pred=None, key=None, avoid=(), extra: float = 0.006):
    cands = []
    for x in _GX:
        for y in _GY:
            if pred is not None and not pred(x, y):
                continue
            cands.append(((key(x, y) if key else 0.0), x, y))
    cands.sort()
    for _, x, y in cands:
        if any(math.hypot(x - a, y - b) < 0.055 for a, b in avoid):
            continue
        if _free_xy(state, (x, y), moving, extra):
            return (float(x), float(y))
    return None


class _Sim:
    def __init__(self, state: WorldState):
        self.state = state
        self.steps: list = []

    def do(self, step) -> None:
        new, fail = apply_skill(self.state, step)
        if fail is not None:
            raise _Fail(fail.reason)
        self.state = new
        self.steps.append(step)

    def try_do(self, step) -> bool:
        try:
            self.do(step)
            return True
        except _Fail:
            return False

    def above(self, b: str) -> list[str]:
        return _chain_up(self.state, b)[1:]

    def to_spot(self, b: str, pred=None, key=None, avoid=(), extra: float = 0.006) -> None:
        if key is None:
            here = _xy(self.state, b)
            key = lambda x, y: math.hypot(x - here[0], y - here[1])  # noqa: E731
        xy = _find_spot(self.state, b, pred, key, avoid, extra)
        if xy is None and extra > 0:
            xy = _find_spot(self.state, b, pred, key, avoid, 0.0)
        if xy is None:
            raise _Fail(f"no free spot for the {b}")
        self.do(PutAt(block=b, position=xy))

    def clear(self, b: str, temp_pred=None, avoid=()) -> None:
        """Move every block stacked on b to a free table spot (top first)."""
        for t in reversed(self.above(b)):
            try:
                self.to_spot(t, temp_pred, avoid=avoid)
            except _Fail:
                self.to_spot(t, None, avoid=avoid)

    def place_region(self, b: str, pred, key, supports=None, allow_bowls: bool = True) -> None:
        """Put the (clear) block b somewhere in a region: a free table spot, else on top of a
        clear block there, else in a bowl there."""
        xy = _find_spot(self.state, b, pred, key)
        if xy is None:
            xy = _find_spot(self.state, b, pred, key, extra=0.0)
        if xy is not None:
            self.do(PutAt(block=b, position=xy))
            return
        own = set(_chain_up(self.state, b))
        rel = relations(self.state)
        cands = [
            s for s in self.state.blocks
            if s not in own and rel.above(s) is None and pred(*_xy(self.state, s))
            and (supports is None or s in supports)
        ]
        cands.sort(key=lambda s: key(*_xy(self.state, s)))
        for s in cands:
            if self.try_do(PutOn(block=b, target=s)):
                return
        if allow_bowls:
            ws = [w for w in self.state.bowls if pred(*_xy(self.state, w))]
            ws.sort(key=lambda w: key(*_xy(self.state, w)))
            for w in ws:
                if self.try_do(PutIn(block=b, bowl=w)):
                    return
        raise _Fail(f"no place for the {b} in the region")

    def evacuate(self, points, keep=(), temp_pred=None) -> None:
        """Move blocks (not in ``keep``) whose footprint would block a block put at any of
        ``points`` to spots away from them."""
        for _ in range(len(self.state.blocks) + 1):
            blockers = [
                b for b in self.state.blocks
                if b not in keep and _z(self.state, b) <= BLOCK_SIZE
                and any(_dist(_xy(self.state, b), p) < BLOCK_SIZE + 0.004 + 0.006 for p in points)
            ]
            if not blockers:
                return
            b = blockers[0]
            self.clear(b, temp_pred, avoid=points)
            self.to_spot(b, temp_pred, avoid=points)
        raise _Fail("could not evacuate")


def _by_z_desc(state: WorldState, blocks) -> list[str]:
    return sorted(blocks, key=lambda b: -_z(state, b))


def _verified(intent: Intention, state: WorldState, steps) -> list | None:
    if steps is None:
        return None
    states, fails = apply_plan(state, list(steps))
    if any(f is not None for f in fails):
        return None
    final = states[-1] if states else state
    return list(steps) if intent.strict(final) else None


def _best_plan(intent: Intention, state: WorldState, strategies) -> list | None:
    """Run each planning strategy; return the shortest plan that verifies."""
    if intent.strict(state):
        return []
    best = None
    for strat in strategies:
        try:
            steps = strat(state)
        except _Fail:
            continue
        steps = _verified(intent, state, steps)
        if steps is not None and (best is None or len(steps) < len(best)):
            best = steps
    return best


# ----------------------------------------------------------------------------------------
# r050: every block into the bowl of its colour; leftovers stacked in the back left corner
# ----------------------------------------------------------------------------------------


class R050(_Base):
    name = "r050"
    description = (
        "Monochrome zoning: every block into a bowl of its colour. "
        "Leftovers stacked neatly in the back left corner."
    )
    CELL = "top left corner"
    CORNER_PT = (-0.26, -0.26)

    def _split(self, state: WorldState):
        bowls = {_color(w): w for w in state.bowls}
        matched = {b: bowls[_color(b)] for b in state.blocks if _color(b) in bowls}
        left = [b for b in state.blocks if b not in matched]
        return matched, left

    def _leftovers_ok(self, state: WorldState, left: list[str], slack: float = 0.0) -> bool:
        if not left:
            return True
        tower = _single_tower(state, left)
        if tower is None:
            return False
        base = tower[0]
        return _on_table(state, base) and _in_region(_xy(state, base), (self.CELL,), slack)

    def _sat(self, state: WorldState, slack: float) -> bool:
        matched, left = self._split(state)
        if any(_in_bowl(state, b) != w for b, w in matched.items()):
            return False
        return self._leftovers_ok(state, left, slack)

    def score(self, state: WorldState) -> float:
        matched, left = self._split(state)
        ok = sum(_in_bowl(state, b) == w for b, w in matched.items())
        ok += sum(_in_bowl(state, b) is None and _in_region(_xy(state, b), (self.CELL,), SLACK) for b in left)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        matching = True if rng.random() < 0.7 else None
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2), matching=matching)

    def _corner_pred(self, x, y):
        return _in_cell(x, y, self.CELL, 0.025)

    def _corner_key(self, x, y):
        return math.hypot(x - self.CORNER_PT[0], y - self.CORNER_PT[1])

    def _strategy(self, state: WorldState) -> list:
        sim = _Sim(state)
        not_corner = lambda x, y: not _in_cell(x, y, self.CELL)  # noqa: E731
        for _ in range(3):
            matched, left = self._split(sim.state)
            for b in _by_z_desc(sim.state, matched):
                if _in_bowl(sim.state, b) == matched[b]:
                    continue
                sim.clear(b, not_corner)
                sim.do(PutIn(block=b, bowl=matched[b]))
            if left and not self._leftovers_ok(sim.state, left):
                rel = relations(sim.state)
                # an existing stack of leftovers standing in the corner can serve as the base
                bases = [
                    b for b in left
                    if rel.below(b) is None and _on_table(sim.state, b) and _cell(sim.state, b) == self.CELL
                ]
                tower = None
                for base in sorted(bases, key=lambda b: -len(_chain_up(sim.state, b))):
                    chain = _chain_up(sim.state, base)
                    if all(t in left for t in chain):
                        tower = chain
                        break
                if tower is None:
                    pick = min(
                        left,
                        key=lambda b: (len(sim.above(b)), _dist(_xy(sim.state, b), self.CORNER_PT)),
                    )
                    sim.clear(pick, not_corner)
                    sim.place_region(pick, self._corner_pred, self._corner_key, supports=(), allow_bowls=False)
                    tower = [pick]
                top_pt = _xy(sim.state, tower[0])
                for b in _by_z_desc(sim.state, [b for b in left if b not in tower]):
                    sim.clear(b, not_corner, avoid=[top_pt])
                    sim.do(PutOn(block=b, target=tower[-1]))
                    tower.append(b)
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [self._strategy])


# ----------------------------------------------------------------------------------------
# r082: all blocks in one column along the right edge, evenly spaced front to back
# ----------------------------------------------------------------------------------------


class R082(_Base):
    name = "r082"
    description = (
        "Align all the blocks along the right edge, front to back, evenly spaced. "
        "Like a column in a layout grid."
    )
    MIN_X = 0.19  # block centres at least this far right (within ~9 cm of the right edge)
    ALIGN_TOL = 0.02  # spread of the column's x
    SPACING_TOL = 0.025  # spread of the gaps (at least; 20 % of the mean gap for wide spacing)
    MIN_GAP = 0.038  # centre spacing: blocks side by side, not on top of each other

    def _block_ok(self, state: WorldState, b: str, slack: float = SLACK) -> bool:
        return _on_table(state, b) and _xy(state, b)[0] >= self.MIN_X + SLACK - slack

    def _sat(self, state: WorldState, slack: float) -> bool:
        blocks = state.blocks
        if not blocks:
            return True
        if not all(self._block_ok(state, b, slack) for b in blocks):
            return False
        xs = [_xy(state, b)[0] for b in blocks]
        if max(xs) - min(xs) > self.ALIGN_TOL:
            return False
        ys = sorted(_xy(state, b)[1] for b in blocks)
        gaps = [b - a for a, b in zip(ys, ys[1:])]
        if gaps:
            tol = max(self.SPACING_TOL, 0.2 * float(np.mean(gaps)))
            if min(gaps) < self.MIN_GAP or max(gaps) - min(gaps) > tol:
                return False
        return True

    def score(self, state: WorldState) -> float:
        ok = sum(self._block_ok(state, b) for b in state.blocks)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return 1 <= len(scene.blocks) <= 9

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _column(self, state: WorldState, n: int, against_blocks: bool):
        ignore = () if against_blocks else tuple(state.blocks)
        for x in (0.27, 0.26, 0.25, 0.24, 0.23, 0.22, 0.21, 0.28):
            if n == 1:
                y_here = _xy(state, state.blocks[0])[1]
                ys = sorted(_GY, key=lambda y: abs(y - y_here))
                for y in ys:
                    if _free_xy(state, (x, y), state.blocks[0], 0.006, ignore):
                        return [(x, float(y))]
                continue
            d_max = min(0.2, 0.5 / (n - 1))
            for d in np.arange(d_max, 0.0449, -0.0025):
                span = d * (n - 1)
                starts = np.arange(-0.75, -0.25 - span + 1e-9, 0.005)
                starts = sorted(starts, key=lambda s: abs(s + span / 2 + 0.5))
                for s in starts:
                    pts = [(x, float(s + i * d)) for i in range(n)]
                    if all(_free_xy(state, p, None, 0.006, ignore) for p in pts):
                        return pts
        return None

    def _strategy(self, state: WorldState, against_blocks: bool) -> list:
        sim = _Sim(state)
        blocks = state.blocks
        pts = self._column(state, len(blocks), against_blocks)
        if pts is None:
            raise _Fail("no room for the column")
        left_pred = lambda x, y: x < 0.12  # noqa: E731
        if not against_blocks:
            sim.evacuate(pts, temp_pred=left_pred)
        # front-most block to the front-most point, and so on (moves do not cross)
        order = sorted(blocks, key=lambda b: _xy(sim.state, b)[1])
        target = dict(zip(order, sorted(pts, key=lambda p: p[1])))
        for b in _by_z_desc(sim.state, blocks):
            sim.clear(b, left_pred, avoid=pts)
            sim.do(PutAt(block=b, position=target[b]))
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(
            self, state, [lambda s: self._strategy(s, True), lambda s: self._strategy(s, False)]
        )


# ----------------------------------------------------------------------------------------
# r110: all blocks to the corners (middle clear)
# ----------------------------------------------------------------------------------------

_CORNER_PTS = [(-0.26, -0.26), (0.26, -0.26), (-0.26, -0.74), (0.26, -0.74)]


def _is_corner_xy(x: float, y: float) -> bool:
    return table_position_name((x, y)) in CORNERS


class R110(_Base):
    name = "r110"
    description = (
        "Keep the middle of the table clear, that's my pass. "
        "All blocks to the corners, doesn't matter which corner."
    )

    def _ok(self, state: WorldState, b: str, slack: float = 0.0) -> bool:
        return _in_region(_xy(state, b), CORNERS, slack)

    def _sat(self, state: WorldState, slack: float) -> bool:
        return all(self._ok(state, b, slack) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        ok = sum(self._ok(state, b, SLACK) for b in state.blocks)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    @staticmethod
    def _pred(x, y):
        return any(_in_cell(x, y, c, 0.02) for c in CORNERS)

    def _strategy(self, state: WorldState) -> list:
        sim = _Sim(state)
        for _ in range(3):
            for b in _by_z_desc(sim.state, sim.state.blocks):
                if self._ok(sim.state, b):
                    continue
                here = _xy(sim.state, b)
                key = lambda x, y, h=here: min(_dist((x, y), c) for c in _CORNER_PTS) + 0.3 * _dist((x, y), h)  # noqa: E731
                sim.clear(b, self._pred)
                sim.place_region(b, self._pred, key, supports={s for s in sim.state.blocks if self._ok(sim.state, s)})
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [self._strategy])


# ----------------------------------------------------------------------------------------
# r158: orange block in front of the blue bowl (when both there); everything else in bowls
# ----------------------------------------------------------------------------------------


class R158(_Base):
    name = "r158"
    description = (
        "Put the orange block in front of the blue bowl if they're both there, "
        "that's the penalty spot. Everything else in bowls."
    )
    ORANGE, BLUE = "orange block", "blue bowl"

    def _rule(self, state: WorldState) -> bool:
        return self.ORANGE in state.positions and self.BLUE in state.positions

    def _in_front(self, state: WorldState) -> bool:
        if not _on_table(state, self.ORANGE):
            return False
        bx, by = _xy(state, self.ORANGE)
        wx, wy = _xy(state, self.BLUE)
        dx, dy = bx - wx, by - wy
        dist = math.hypot(dx, dy)
        return dy < 0 and abs(dx) <= 0.6 * abs(dy) and 0.075 <= dist <= 0.20

    def _ok(self, state: WorldState, b: str) -> bool:
        if b == self.ORANGE and self._rule(state):
            return self._in_front(state)
        return _in_bowl(state, b) is not None

    def _sat(self, state: WorldState, slack: float) -> bool:
        return all(self._ok(state, b) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        ok = sum(self._ok(state, b) for b in state.blocks)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        if rng.random() < 0.75:
            nb = int(rng.integers(2, 4))
            nw = int(rng.integers(1, 3))
            return _scene_with(rng, ["orange"], ["blue"], nb, nw)
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _place_orange(self, sim: _Sim) -> bool:
        try:
            sim.clear(self.ORANGE)
        except _Fail:
            return False
        if sim.try_do(PutNextTo(block=self.ORANGE, target=self.BLUE, side="front")):
            if self._in_front(sim.state):
                return True
        wx, wy = _xy(sim.state, self.BLUE)
        ideal = (wx, wy - 0.105)

        def pred(x, y):
            dx, dy = x - wx, y - wy
            d = math.hypot(dx, dy)
            return dy < 0 and abs(dx) <= 0.45 * abs(dy) and 0.09 <= d <= 0.18

        xy = _find_spot(sim.state, self.ORANGE, pred, lambda x, y: _dist((x, y), ideal), extra=0.003)
        if xy is None:
            # points just off the 1 cm grid, down to the reach limit
            for y in np.arange(wy - 0.09, max(wy - 0.18, -0.82) - 1e-9, -0.005):
                for x in (wx, wx - 0.01, wx + 0.01, wx - 0.02, wx + 0.02):
                    if pred(x, y) and sim.try_do(PutAt(block=self.ORANGE, position=(float(x), float(y)))):
                        return True
            return False
        return sim.try_do(PutAt(block=self.ORANGE, position=xy))

    def _strategy(self, state: WorldState, orange_first: bool) -> list:
        sim = _Sim(state)
        rule = self._rule(state)
        front_pt = None
        if rule:
            wx, wy = _xy(state, self.BLUE)
            front_pt = [(wx, wy - 0.097)]
        for _ in range(3):
            if rule and orange_first and not self._in_front(sim.state):
                self._place_orange(sim)
            others = [b for b in sim.state.blocks if not (rule and b == self.ORANGE)]
            for b in _by_z_desc(sim.state, others):
                if _in_bowl(sim.state, b) is not None:
                    continue
                sim.clear(b, avoid=front_pt or ())
                exclude = set()
                if rule and _in_bowl(sim.state, self.ORANGE):
                    exclude.add(_in_bowl(sim.state, self.ORANGE))
                w = _nearest_bowl(sim.state, b, exclude)
                if w is None:
                    raise _Fail("no bowl")
                sim.do(PutIn(block=b, bowl=w))
            if rule and not self._in_front(sim.state):
                if not self._place_orange(sim):
                    raise _Fail("no penalty spot")
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(
            self, state, [lambda s: self._strategy(s, False), lambda s: self._strategy(s, True)]
        )


# ----------------------------------------------------------------------------------------
# r208: everything into the bowl closest to the middle
# ----------------------------------------------------------------------------------------


class R208(_Base):
    name = "r208"
    description = "Just put everything in one bowl, whichever bowl is closest to the middle. Fewest moves wins."
    TIE = 0.01  # bowls whose distances to the middle differ by less are equally "closest"

    def _targets(self, state: WorldState) -> list[str]:
        if not state.bowls:
            return []
        d = {w: _dist(_xy(state, w), CENTRE) for w in state.bowls}
        m = min(d.values())
        return sorted((w for w in d if d[w] <= m + self.TIE), key=lambda w: d[w])

    def _sat(self, state: WorldState, slack: float) -> bool:
        if not state.blocks:
            return True
        return any(all(_in_bowl(state, b) == w for b in state.blocks) for w in self._targets(state))

    def score(self, state: WorldState) -> float:
        targets = self._targets(state)
        ok = max((sum(_in_bowl(state, b) == w for b in state.blocks) for w in targets), default=0)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _strategy(self, state: WorldState, w: str) -> list:
        sim = _Sim(state)
        for b in _by_z_desc(sim.state, sim.state.blocks):
            if _in_bowl(sim.state, b) == w:
                continue
            sim.clear(b)
            sim.do(PutIn(block=b, bowl=w))
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [lambda s, w=w: self._strategy(s, w) for w in self._targets(state)])


# ----------------------------------------------------------------------------------------
# r253: all blocks at the back
# ----------------------------------------------------------------------------------------


class R253(_Base):
    name = "r253"
    description = (
        "Nothing near the front edge. The dogs put their noses on the table. Keep all the blocks at the back."
    )
    BACK_Y = -0.4  # the back third of the table

    def _ok(self, state: WorldState, b: str, slack: float = 0.0) -> bool:
        return _xy(state, b)[1] >= self.BACK_Y - slack

    def _sat(self, state: WorldState, slack: float) -> bool:
        return all(self._ok(state, b, slack) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        ok = sum(self._ok(state, b, SLACK) for b in state.blocks)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _strategy(self, state: WorldState) -> list:
        sim = _Sim(state)
        pred = lambda x, y: y >= self.BACK_Y + 0.025  # noqa: E731
        for _ in range(3):
            for b in _by_z_desc(sim.state, sim.state.blocks):
                if self._ok(sim.state, b):
                    continue
                hx = _xy(sim.state, b)[0]
                key = lambda x, y, hx=hx: abs(y + 0.28) + 0.3 * abs(x - hx)  # noqa: E731
                sim.clear(b, pred)
                sim.place_region(b, pred, key, supports={s for s in sim.state.blocks if self._ok(sim.state, s)})
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [self._strategy])


# ----------------------------------------------------------------------------------------
# r277: one tower of all blocks in a back corner
# ----------------------------------------------------------------------------------------


class R277(_Base):
    name = "r277"
    description = "Stack them all in one tower in the back corner, far from the front where little hands reach."
    CELLS = ("top left corner", "top right corner")
    PTS = [(-0.26, -0.26), (0.26, -0.26)]

    def _sat(self, state: WorldState, slack: float) -> bool:
        blocks = state.blocks
        if not blocks:
            return True
        tower = _single_tower(state, blocks)
        if tower is None:
            return False
        return _in_region(_xy(state, tower[0]), self.CELLS, slack)

    def score(self, state: WorldState) -> float:
        blocks = state.blocks
        if not blocks:
            return 1.0
        # the largest stack standing in a back corner
        best = 0
        for t in _towers(state):
            if _in_region(_xy(state, t[0]), self.CELLS, SLACK):
                best = max(best, len(t))
        return _score(best, len(blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _pred(self, x, y):
        return any(_in_cell(x, y, c, 0.025) for c in self.CELLS)

    def _key(self, x, y):
        return min(_dist((x, y), p) for p in self.PTS)

    def _strategy(self, state: WorldState, reuse: bool) -> list:
        sim = _Sim(state)
        tower = None
        if reuse:
            bases = [t for t in _towers(sim.state) if _cell(sim.state, t[0]) in self.CELLS]
            if bases:
                tower = max(bases, key=len)
        if tower is None:
            pick = min(sim.state.blocks, key=lambda b: (len(sim.above(b)), self._key(*_xy(sim.state, b))))
            sim.clear(pick)
            sim.place_region(pick, self._pred, self._key, supports=(), allow_bowls=False)
            tower = [pick]
        pt = [_xy(sim.state, tower[0])]
        for b in _by_z_desc(sim.state, [b for b in sim.state.blocks if b not in tower]):
            sim.clear(b, avoid=pt)
            sim.do(PutOn(block=b, target=tower[-1]))
            tower.append(b)
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [lambda s: self._strategy(s, True), lambda s: self._strategy(s, False)])


# ----------------------------------------------------------------------------------------
# r017: staircase 1, 2, 3, ... stacked blocks from left to right
# ----------------------------------------------------------------------------------------


def _stair_heights(n: int) -> list[int]:
    out, k = [], 1
    while n > 0:
        out.append(min(k, n))
        n -= out[-1]
        k += 1
    return out


class R017(_Base):
    name = "r017"
    description = (
        "Make a staircase: one block on its own, then two stacked, then three stacked, "
        "left to right, as far as the blocks go."
    )
    PITCH = 0.055
    DX = (0.03, 0.10)  # centre spacing of neighbouring columns
    DY = 0.03  # columns stand in one row

    def _columns(self, state: WorldState) -> list[list[str]] | None:
        towers = _towers(state)
        if sum(len(t) for t in towers) != len(state.blocks):
            return None
        if not all(_on_table(state, t[0]) for t in towers):
            return None
        return sorted(towers, key=lambda t: _xy(state, t[0])[0])

    def _sat(self, state: WorldState, slack: float) -> bool:
        if not state.blocks:
            return True
        cols = self._columns(state)
        if cols is None:
            return False
        h = [len(c) for c in cols]
        k = len(h)
        if any(h[i] != i + 1 for i in range(k - 1)) or not 1 <= h[-1] <= k:
            return False
        for a, b in zip(cols, cols[1:]):
            (ax, ay), (bx, by) = _xy(state, a[0]), _xy(state, b[0])
            if not (self.DX[0] <= bx - ax <= self.DX[1]) or abs(by - ay) > self.DY:
                return False
        return True

    def score(self, state: WorldState) -> float:
        n = len(state.blocks)
        if n == 0:
            return 1.0
        cols = self._columns(state)
        ok = 0
        if cols is not None:
            for i, c in enumerate(cols):
                if len(c) == i + 1 or (i == len(cols) - 1 and len(c) <= i + 1):
                    ok += len(c)
                else:
                    break
        return _score(ok, n, self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return 3 <= len(scene.blocks) <= 9

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        nb = int(rng.integers(3, 5))
        nw = int(rng.integers(0, 6 - nb))
        return sample_scene(rng, n_blocks=nb, n_bowls=nw)

    def _row(self, state: WorldState, k: int, against_blocks: bool):
        ignore = () if against_blocks else tuple(state.blocks)
        width = self.PITCH * (k - 1)
        x_starts = sorted(np.arange(-0.27, 0.27 - width + 1e-9, 0.01), key=lambda s: abs(s + width / 2))
        ys = sorted(np.arange(-0.74, -0.2599, 0.01), key=lambda y: abs(y + 0.5))
        for y in ys:
            for s in x_starts:
                pts = [(float(s + i * self.PITCH), float(y)) for i in range(k)]
                if all(_free_xy(state, p, None, 0.006, ignore) for p in pts):
                    return pts
        return None

    def _strategy(self, state: WorldState, against_blocks: bool) -> list:
        sim = _Sim(state)
        heights = _stair_heights(len(state.blocks))
        pts = self._row(state, len(heights), against_blocks)
        if pts is None:
            raise _Fail("no room for the staircase")
        if not against_blocks:
            sim.evacuate(pts)
        order = _by_z_desc(sim.state, sim.state.blocks)
        j = 0
        for p, h in zip(pts, heights):
            prev = None
            for level in range(h):
                b = order[j]
                j += 1
                sim.clear(b, avoid=pts)
                if level == 0:
                    sim.do(PutAt(block=b, position=p))
                else:
                    sim.do(PutOn(block=b, target=prev))
                prev = b
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [lambda s: self._strategy(s, True), lambda s: self._strategy(s, False)])


# ----------------------------------------------------------------------------------------
# r123: pink on purple, cyan on blue; the rest in bowls
# ----------------------------------------------------------------------------------------


class R123(_Base):
    name = "r123"
    description = "Put the pink block on top of the purple one, and the cyan on top of the blue. The rest go in bowls."
    PAIRS = (("pink block", "purple block"), ("cyan block", "blue block"))

    def _pairs(self, state: WorldState):
        return [(t, b) for t, b in self.PAIRS if t in state.positions and b in state.positions]

    def _rest(self, state: WorldState):
        paired = {x for p in self._pairs(state) for x in p}
        return [b for b in state.blocks if b not in paired]

    def _sat(self, state: WorldState, slack: float) -> bool:
        rel = relations(state)
        if any(rel.below(t) != b for t, b in self._pairs(state)):
            return False
        return all(_in_bowl(state, b) is not None for b in self._rest(state))

    def score(self, state: WorldState) -> float:
        rel = relations(state)
        ok = sum(2 for t, b in self._pairs(state) if rel.below(t) == b)
        ok += sum(_in_bowl(state, b) is not None for b in self._rest(state))
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        if not scene.blocks:
            return False
        names = set(scene.objects)
        paired = {x for p in self.PAIRS if p[0] in names and p[1] in names for x in p}
        rest = [b for b in scene.blocks if b not in paired]
        return not rest or len(scene.bowls) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        r = rng.random()
        if r < 0.2:
            must = ["pink", "purple", "cyan", "blue"]
            return _scene_with(rng, must, [], 4, 1)
        must = ["pink", "purple"] if r < 0.6 else ["cyan", "blue"]
        nb = int(rng.integers(2, 4))
        nw = int(rng.integers(1, 3))
        return _scene_with(rng, must, [], nb, nw)

    def _strategy(self, state: WorldState) -> list:
        sim = _Sim(state)
        for _ in range(4):
            rel = relations(sim.state)
            pair_bowls = set()
            for t, b in self._pairs(sim.state):
                if rel.below(t) != b:
                    sim.clear(b)
                    sim.clear(t)
                    # a pair's bottom stacked on a block that must go elsewhere: put it on the table
                    if relations(sim.state).below(b) is not None:
                        sim.to_spot(b)
                    sim.do(PutOn(block=t, target=b))
                    rel = relations(sim.state)
                for x in (t, b):
                    if (w := _in_bowl(sim.state, x)) is not None:
                        pair_bowls.add(w)
            for b in _by_z_desc(sim.state, self._rest(sim.state)):
                if _in_bowl(sim.state, b) is not None:
                    continue
                sim.clear(b)
                w = _nearest_bowl(sim.state, b, pair_bowls)
                if w is None:
                    raise _Fail("no bowl")
                sim.do(PutIn(block=b, bowl=w))
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [self._strategy])


# ----------------------------------------------------------------------------------------
# r204: nothing in the corners; corner blocks go to the centre
# ----------------------------------------------------------------------------------------


class R204(_Base):
    name = "r204"
    description = "Nothing in the corners. Ever. If a block is in a corner, move it to the centre."

    def _ok(self, state: WorldState, b: str, slack: float = 0.0) -> bool:
        return _in_region(_xy(state, b), NON_CORNERS, slack)

    def _sat(self, state: WorldState, slack: float) -> bool:
        return all(self._ok(state, b, slack) for b in state.blocks)

    def score(self, state: WorldState) -> float:
        ok = sum(self._ok(state, b, SLACK) for b in state.blocks)
        return _score(ok, len(state.blocks), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _strategy(self, state: WorldState) -> list:
        sim = _Sim(state)
        pred = lambda x, y: _in_cell(x, y, "middle", 0.02)  # noqa: E731
        key = lambda x, y: _dist((x, y), CENTRE)  # noqa: E731
        not_corner = lambda x, y: not _is_corner_xy(x, y)  # noqa: E731
        for _ in range(3):
            for b in _by_z_desc(sim.state, sim.state.blocks):
                if self._ok(sim.state, b):
                    continue
                sim.clear(b, not_corner)
                sim.place_region(b, pred, key)
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [self._strategy])


# ----------------------------------------------------------------------------------------
# r248: red top left, blue top right, yellow bottom middle
# ----------------------------------------------------------------------------------------


class R248(_Base):
    name = "r248"
    description = "Red block top left, blue block top right, yellow block bottom middle. It's a Mondrian thing, don't ask."
    TARGETS = {
        "red block": ("top left corner", (-0.25, -0.25)),
        "blue block": ("top right corner", (0.25, -0.25)),
        "yellow block": ("bottom side", (0.0, -0.75)),
    }

    def _named(self, state: WorldState) -> list[str]:
        return [b for b in self.TARGETS if b in state.positions]

    def _ok(self, state: WorldState, b: str, slack: float = 0.0) -> bool:
        return _in_region(_xy(state, b), (self.TARGETS[b][0],), slack)

    def _sat(self, state: WorldState, slack: float) -> bool:
        return all(self._ok(state, b, slack) for b in self._named(state))

    def score(self, state: WorldState) -> float:
        named = self._named(state)
        if not named:
            return 1.0
        ok = sum(self._ok(state, b, SLACK) for b in named)
        return _score(ok, len(named), self.satisfied(state))

    def feasible(self, scene: Scene) -> bool:
        return any(b in scene.objects for b in self.TARGETS)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        k = int(rng.integers(1, 4))
        must = [str(c) for c in rng.choice(["red", "blue", "yellow"], size=k, replace=False)]
        nb = k + int(rng.integers(0, 2))
        nw = int(rng.integers(max(0, 3 - nb), 6 - nb))
        nw = min(nw, 2)
        return _scene_with(rng, must, [], nb, nw)

    def _strategy(self, state: WorldState) -> list:
        sim = _Sim(state)
        cells = {c for c, _ in self.TARGETS.values()}
        temp = lambda x, y: table_position_name((x, y)) not in cells  # noqa: E731
        for _ in range(4):
            named = self._named(sim.state)
            for b in _by_z_desc(sim.state, named):
                if self._ok(sim.state, b):
                    continue
                cell, pt = self.TARGETS[b]
                sim.clear(b, temp)
                supports = {s for s in sim.state.blocks if s not in named or self._ok(sim.state, s)}
                sim.place_region(
                    b,
                    lambda x, y, c=cell: _in_cell(x, y, c, 0.025),
                    lambda x, y, p=pt: _dist((x, y), p),
                    supports=supports,
                )
            if self.strict(sim.state):
                break
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        return _best_plan(self, state, [self._strategy])


# ----------------------------------------------------------------------------------------
# r329: a tower of two in the front middle
# ----------------------------------------------------------------------------------------


class R329(_Base):
    name = "r329"
    description = (
        "My kid's here weekends \u2014 leave a little tower of two in the front middle "
        "so she's got something to knock over when she comes in."
    )
    CELL = "bottom side"
    PT = (0.0, -0.72)

    def _front_towers(self, state: WorldState, slack: float = 0.0) -> list[list[str]]:
        return [
            t for t in _towers(state)
            if _on_table(state, t[0]) and _in_region(_xy(state, t[0]), (self.CELL,), slack)
        ]

    def _sat(self, state: WorldState, slack: float) -> bool:
        return any(len(t) == 2 for t in self._front_towers(state, slack))

    def score(self, state: WorldState) -> float:
        if self.satisfied(state):
            return 1.0
        towers = self._front_towers(state, SLACK)
        if not towers:
            return 0.0
        return 0.5 if any(len(t) >= 1 for t in towers) else 0.0

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 2

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=(1, 2))

    def _pred(self, x, y):
        return _in_cell(x, y, self.CELL, 0.025)

    def _key(self, x, y):
        return _dist((x, y), self.PT)

    def _not_front(self, x, y):
        return table_position_name((x, y)) != self.CELL

    def _grow(self, sim: _Sim, tower: list[str]) -> None:
        """Bring the tower standing in the front middle to exactly two blocks."""
        if len(tower) > 2:
            for t in reversed(tower[2:]):
                sim.to_spot(t, self._not_front)
            return
        # put one more block on top: the cheapest block to free
        others = [b for b in sim.state.blocks if b not in tower]
        if not others:
            raise _Fail("only one block")
        b = min(others, key=lambda b: (len(sim.above(b)), _dist(_xy(sim.state, b), _xy(sim.state, tower[0]))))
        sim.clear(b, self._not_front, avoid=[_xy(sim.state, tower[0])])
        sim.do(PutOn(block=b, target=tower[0]))

    def _reuse(self, state: WorldState, which: int) -> list:
        sim = _Sim(state)
        towers = sorted(self._front_towers(sim.state), key=lambda t: abs(len(t) - 2))
        if which >= len(towers):
            raise _Fail("no such tower")
        self._grow(sim, towers[which])
        return sim.steps

    def _new(self, state: WorldState) -> list:
        sim = _Sim(state)
        blocks = sim.state.blocks
        if len(blocks) < 2:
            raise _Fail("too few blocks")
        base = min(blocks, key=lambda b: (len(sim.above(b)), self._key(*_xy(sim.state, b))))
        sim.clear(base, self._not_front)
        sim.place_region(base, self._pred, self._key, supports=(), allow_bowls=False)
        self._grow(sim, [base])
        return sim.steps

    def plan(self, state: WorldState) -> list | None:
        strategies = [lambda s, i=i: self._reuse(s, i) for i in range(3)] + [self._new]
        return _best_plan(self, state, strategies)


CLASSES = [R050, R082, R110, R158, R208, R253, R277, R017, R123, R204, R248, R329]
