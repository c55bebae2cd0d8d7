"""Checkers for requests r048, r081, r095, r152, r191, r252, r273, r335, r099, r177, r243, r314.

Each class judges a final table (satisfied / score), says whether a scene can show the request
(feasible), samples such scenes (sample_scene) and plans a way to a satisfying table (plan) under
the symbolic world model.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import (
    BLOCK_SIZE,
    BOUNDS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    WorldState,
    apply_plan,
    apply_skill,
    relations,
    sample_scene,
)

(X0, X1), (Y0, Y1) = BOUNDS  # x in [-0.3, 0.3] left->right, y in [-0.8, -0.2] front->back
MIDDLE = np.array([(X0 + X1) / 2, (Y0 + Y1) / 2])
TABLE_Z_TOL = 0.012
NEXT_OFFSET = 0.065 + BLOCK_SIZE / 2 + 0.012  # where PutNextTo puts a block beside a bowl
SIDE_UNITS = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "front": (0.0, -1.0), "behind": (0.0, 1.0)}


# --------------------------------------------------------------------------- helpers
def _color(name: str) -> str:
    return name.split(" ", 1)[0]


def _xy(state: WorldState, name: str) -> np.ndarray:
    return np.asarray(state.positions[name][:2], dtype=float)


def _loose_on_table(state: WorldState, b: str) -> bool:
    """Resting directly on the table (not in a bowl, not on another block)."""
    rel = relations(state)
    return b in rel.on_table and rel.in_bowl(b) is None and rel.below(b) is None


def _chain_above(state: WorldState, b: str) -> list[str]:
    """Blocks stacked above b, bottom-up."""
    rel = relations(state)
    out, cur = [], b
    for _ in range(20):
        top = rel.above(cur)
        if top is None or top in out:
            break
        out.append(top)
        cur = top
    return out


def _try(state: WorldState, step) -> WorldState | None:
    new, fail = apply_skill(state, step)
    return None if fail is not None else new


def _edge_dist(xy) -> float:
    x, y = float(xy[0]), float(xy[1])
    return min(x - X0, X1 - x, y - Y0, Y1 - y)


def _grid(step: float = 0.04, inset: float = 0.035) -> list[tuple[float, float]]:
    xs = np.arange(X0 + inset, X1 - inset + 1e-9, step)
    ys = np.arange(Y0 + inset, Y1 - inset + 1e-9, step)
    return [(float(x), float(y)) for x in xs for y in ys]


_GRID = _grid()


def _park(state, block, steps, avoid=(), avoid_r=0.1, prefer=None):
    """Put ``block`` on a free table spot (away from ``avoid`` points); returns the new state or None."""
    ref = np.asarray(prefer if prefer is not None else _xy(state, block), dtype=float)
    cands = [p for p in _GRID if all(math.hypot(p[0] - a[0], p[1] - a[1]) >= avoid_r for a in avoid)]
    cands.sort(key=lambda p: math.hypot(p[0] - ref[0], p[1] - ref[1]))
    for p in cands:
        step = PutAt(block=block, position=p)
        new = _try(state, step)
        if new is not None:
            steps.append(step)
            return new
    return None


def _clear(state, block, steps, avoid=(), avoid_r=0.1):
    """Park everything stacked above ``block`` (top first)."""
    for top in reversed(_chain_above(state, block)):
        state = _park(state, top, steps, avoid, avoid_r)
        if state is None:
            return None
    return state


def _check(intention, state, steps):
    """Return steps if they run without failure and reach a satisfying table, else None."""
    if steps is None or state is None:
        return None
    states, fails = apply_plan(state, steps)
    if any(f is not None for f in fails):
        return None
    final = states[-1] if states else state
    return steps if intention.satisfied(final) else None


def _sample(rng, feasible, n_blocks=(2, 3), n_bowls=(1, 2), matching=None, max_objects=5):
    for _ in range(10000):
        nb = n_blocks if isinstance(n_blocks, int) else int(rng.integers(n_blocks[0], n_blocks[1] + 1))
        nw = n_bowls if isinstance(n_bowls, int) else int(rng.integers(n_bowls[0], n_bowls[1] + 1))
        if not 3 <= nb + nw <= max_objects:
            continue
        scene = sample_scene(rng, n_blocks=nb, n_bowls=nw, matching=matching)
        if feasible(scene):
            return scene
    raise RuntimeError("could not sample a feasible scene")


# --------------------------------------------------------------------------- r048
class R048(Intention):
    name = "r048"
    description = (
        "Put each block behind the bowl of the same colour. Feels like a proper elevation, "
        "objects in front, blocks behind."
    )

    @staticmethod
    def _pairs(names) -> list[tuple[str, str]]:
        names = list(names)
        return [
            (b, f"{_color(b)} bowl")
            for b in names
            if b.endswith(" block") and f"{_color(b)} bowl" in names
        ]

    @staticmethod
    def _behind(state, b, w, strict: bool = False) -> bool:
        """Directly behind its bowl, on the table (strict: with a margin for settling noise)."""
        if not _loose_on_table(state, b):
            return False
        d = _xy(state, b) - _xy(state, w)
        if strict:
            return 0.08 <= d[1] <= 0.145 and abs(d[0]) <= 0.045
        return 0.07 <= d[1] <= 0.16 and abs(d[0]) <= 0.06

    def satisfied(self, state):
        return all(self._behind(state, b, w) for b, w in self._pairs(state.positions))

    def score(self, state):
        pairs = self._pairs(state.positions)
        if not pairs:
            return 1.0
        return sum(self._behind(state, b, w) for b, w in pairs) / len(pairs)

    def feasible(self, scene):
        return len(self._pairs(scene.objects)) > 0

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 3), (1, 2), matching=True)

    def plan(self, state):
        start, steps = state, []
        pairs = self._pairs(state.positions)
        spots = [tuple(_xy(state, w) + np.array([0.0, NEXT_OFFSET])) for _, w in pairs]
        for _ in range(3 * len(pairs) + 6):
            todo = [(b, w) for b, w in pairs if not self._behind(state, b, w, strict=True)]
            if not todo:
                break
            b, w = todo[0]
            done = {x for x, y in pairs if self._behind(state, x, y, strict=True)}
            state = _clear(state, b, steps, avoid=spots)
            if state is None:
                return None
            new = _try(state, PutNextTo(block=b, target=w, side="behind"))
            if new is not None:
                steps.append(PutNextTo(block=b, target=w, side="behind"))
                state = new
                continue
            wxy = _xy(state, w)
            placed = False
            for dy in (NEXT_OFFSET, 0.11, 0.125, 0.14):
                for dx in (0.0, -0.02, 0.02, -0.04, 0.04):
                    p = (float(wxy[0] + dx), float(wxy[1] + dy))
                    new = _try(state, PutAt(block=b, position=p))
                    if new is not None:
                        steps.append(PutAt(block=b, position=p))
                        state, placed = new, True
                        break
                if placed:
                    break
            if placed:
                continue
            # something movable is in the way: park blocks near the spot that are not done
            spot = wxy + np.array([0.0, NEXT_OFFSET])
            blockers = [
                o for o in state.blocks
                if o != b and o not in done and float(np.hypot(*(_xy(state, o) - spot))) < 0.07
            ]
            if not blockers:
                return None
            for o in blockers:
                state = _clear(state, o, steps, avoid=spots)
                if state is None:
                    return None
                state = _park(state, o, steps, avoid=spots + [tuple(wxy)], avoid_r=0.12)
                if state is None:
                    return None
        return _check(self, start, steps)


# --------------------------------------------------------------------------- r081
class R081(Intention):
    name = "r081"
    description = "Pink on top of whatever's stacked. Always pink on top, it's my accent colour."
    PINK = "pink block"

    def _status(self, state):
        """(pink on a block, nothing on pink, no other stack elsewhere)."""
        rel = relations(state)
        p = self.PINK
        below_chain = []
        cur = p
        for _ in range(20):
            nxt = rel.below(cur)
            if nxt is None or nxt in below_chain:
                break
            below_chain.append(nxt)
            cur = nxt
        on_block = bool(below_chain)
        top = rel.above(p) is None
        others = [b for b in state.blocks if rel.above(b) is not None and b not in below_chain and b != p]
        return on_block, top, not others

    def satisfied(self, state):
        if self.PINK not in state.positions:
            return True  # nothing pink: nothing to put on top
        return all(self._status(state))

    def score(self, state):
        if self.PINK not in state.positions:
            return 1.0
        on_block, top, alone = self._status(state)
        if on_block and top and alone:
            return 1.0
        return 0.5 * float(on_block and top) + 0.25 * float(top and not on_block) + 0.2 * float(alone and on_block)

    def feasible(self, scene):
        return self.PINK in scene.objects and len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 4), (1, 2))

    def plan(self, state):
        start, steps, p = state, [], self.PINK
        if p not in state.positions or len(state.blocks) < 2:
            return None
        for _ in range(30):
            if self.satisfied(state):
                break
            rel = relations(state)
            chain = _chain_above(state, p)
            if chain:  # something on pink: take it off
                state = _park(state, chain[-1], steps)
                if state is None:
                    return None
                continue
            below = []
            cur = p
            while (nxt := rel.below(cur)) is not None and nxt not in below:
                below.append(nxt)
                cur = nxt
            other_tops = [
                b for b in state.blocks
                if b != p and b not in below and rel.above(b) is None and rel.below(b) is not None
            ]
            if below:  # pink tops a stack: dismantle any other stack
                if not other_tops:
                    return None
                state = _park(state, other_tops[0], steps)
                if state is None:
                    return None
                continue
            # pink is loose: put it on the tallest other stack, else on the nearest free block
            if other_tops:
                target = max(other_tops, key=lambda b: state.positions[b][2])
            else:
                cands = [b for b in state.blocks if b != p and rel.above(b) is None]
                if not cands:
                    return None
                target = min(cands, key=lambda b: float(np.hypot(*(_xy(state, b) - _xy(state, p)))))
            step = PutOn(block=p, target=target)
            new = _try(state, step)
            if new is None:
                return None
            steps.append(step)
            state = new
        return _check(self, start, steps)


# --------------------------------------------------------------------------- front rows
FRONT_Y_MAX = -0.72  # a block centre this close to the front edge is "along the front edge"


def _row_ok(state, b, ref_y) -> bool:
    if not _loose_on_table(state, b):
        return False
    y = state.positions[b][1]
    return y <= FRONT_Y_MAX and abs(y - ref_y) <= 0.015


def _front_row_satisfied(state) -> bool:
    blocks = state.blocks
    if not blocks:
        return True
    if any(not _loose_on_table(state, b) for b in blocks):
        return False
    ys = [state.positions[b][1] for b in blocks]
    if max(ys) > FRONT_Y_MAX or max(ys) - min(ys) > 0.03:
        return False
    xs = sorted(state.positions[b][0] for b in blocks)
    return all(b - a >= 0.03 for a, b in zip(xs, xs[1:]))


def _front_row_score(state) -> float:
    blocks = state.blocks
    if not blocks:
        return 1.0
    if _front_row_satisfied(state):
        return 1.0
    ys = [state.positions[b][1] for b in blocks if _loose_on_table(state, b) and state.positions[b][1] <= FRONT_Y_MAX]
    ref = float(np.median(ys)) if ys else Y0 + 0.02
    return min(0.99, sum(_row_ok(state, b, ref) for b in blocks) / len(blocks))


def _front_row_plan(state) -> list | None:
    blocks = sorted(state.blocks, key=lambda b: (-state.positions[b][2], state.positions[b][0]))
    for y in (-0.78, -0.79, -0.80, -0.81, -0.77):
        for pitch in (0.06, 0.05):
            cur, steps, last = state, [], None
            ok = True
            for b in blocks:
                x = X0 + 0.01 if last is None else last + pitch
                placed = False
                while x <= X1 + 0.015:
                    step = PutAt(block=b, position=(round(float(x), 4), y))
                    new = _try(cur, step)
                    if new is not None:
                        cur, last, placed = new, x, True
                        steps.append(step)
                        break
                    x += 0.005
                if not placed:
                    ok = False
                    break
            if ok and _front_row_satisfied(cur):
                return steps
    return None


class R095(Intention):
    name = "r095"
    description = "Keep the bowls empty, love. Line the blocks up along the front edge instead."

    def satisfied(self, state):
        return not relations(state).inside and _front_row_satisfied(state)

    def score(self, state):
        return _front_row_score(state)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 4), (1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        return _check(self, state, _front_row_plan(state))


class R252(Intention):
    name = "r252"
    description = (
        "make it a palette: all the blocks in a row along the front edge, bowls are the water jars, "
        "don't touch them"
    )

    def satisfied(self, state):
        return not relations(state).inside and _front_row_satisfied(state)

    def score(self, state):
        return _front_row_score(state)

    def feasible(self, scene):
        return len(scene.blocks) >= 2

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 4), (1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        return _check(self, state, _front_row_plan(state))


# --------------------------------------------------------------------------- r152
class R152(Intention):
    name = "r152"
    description = "Green block in the middle of the table, it's the pitch. Other blocks spread around the edges."
    GREEN = "green block"
    MID_TOL = 0.08
    EDGE_TOL = 0.08
    SPREAD = 0.10

    def _green_ok(self, state) -> bool:
        g = self.GREEN
        rel = relations(state)
        if rel.above(g) is not None:
            return False
        if not (_loose_on_table(state, g) or (rel.in_bowl(g) is not None and rel.below(g) is None)):
            return False
        return float(np.hypot(*(_xy(state, g) - MIDDLE))) <= self.MID_TOL

    def _others(self, state):
        return [b for b in state.blocks if b != self.GREEN]

    def _at_edge(self, state, b) -> bool:
        return _loose_on_table(state, b) and _edge_dist(_xy(state, b)) <= self.EDGE_TOL

    def satisfied(self, state):
        if self.GREEN not in state.positions:
            return True
        if not self._green_ok(state):
            return False
        others = self._others(state)
        if not all(self._at_edge(state, b) for b in others):
            return False
        return all(
            float(np.hypot(*(_xy(state, a) - _xy(state, b)))) >= self.SPREAD
            for a, b in itertools.combinations(others, 2)
        )

    def score(self, state):
        if self.GREEN not in state.positions:
            return 1.0
        if self.satisfied(state):
            return 1.0
        blocks = state.blocks
        good = int(self._green_ok(state)) + sum(self._at_edge(state, b) for b in self._others(state))
        return min(0.99, good / len(blocks))

    def feasible(self, scene):
        return self.GREEN in scene.objects

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 4), (1, 2))

    def _edge_candidates(self):
        pts = []
        for inset in (0.03, 0.05):
            for y in np.arange(Y0 + inset, Y1 - inset + 1e-9, 0.03):
                pts += [(X0 + inset, float(y)), (X1 - inset, float(y))]
            for x in np.arange(X0 + inset, X1 - inset + 1e-9, 0.03):
                pts += [(float(x), Y0 + inset), (float(x), Y1 - inset)]
        return [(round(float(a), 4), round(float(b), 4)) for a, b in pts]

    def plan(self, state):
        start, steps, g = state, [], self.GREEN
        if g not in state.positions:
            return None
        edge_pts = self._edge_candidates()
        # others already well placed stay where they are
        done: list[str] = []
        for b in sorted(self._others(state), key=lambda b: _edge_dist(_xy(state, b))):
            if (
                self._at_edge(state, b)
                and _edge_dist(_xy(state, b)) <= self.EDGE_TOL - 0.01
                and relations(state).above(b) is None
                and all(float(np.hypot(*(_xy(state, b) - _xy(state, o)))) >= self.SPREAD + 0.01 for o in done)
            ):
                done.append(b)
        for _ in range(20):
            rel = relations(state)
            pending = [b for b in self._others(state) if b not in done]
            movable = [b for b in pending if rel.above(b) is None]
            if movable:
                b = max(movable, key=lambda b: state.positions[b][2])
                placed = [_xy(state, o) for o in done]
                best, best_key = None, None
                here = _xy(state, b)
                for p in edge_pts:
                    pa = np.array(p)
                    spread = min((float(np.hypot(*(pa - q))) for q in placed), default=1.0)
                    key = (round(min(spread, 0.3), 3), -float(np.hypot(*(pa - here))))
                    if best_key is not None and key <= best_key:
                        continue
                    if _try(state, PutAt(block=b, position=p)) is None:
                        continue
                    best, best_key = p, key
                if best is None:
                    return None
                steps.append(PutAt(block=b, position=best))
                state = _try(state, steps[-1])
                done.append(b)
                continue
            if pending:
                # only the green block can be on top of pending ones: move it first
                if rel.above(g) is not None:
                    return None
                state = self._green_to_middle(state, steps)
                if state is None:
                    return None
                continue
            if not self._green_ok(state):
                state = _clear(state, g, steps)
                if state is None:
                    return None
                state = self._green_to_middle(state, steps)
                if state is None:
                    return None
            break
        return _check(self, start, steps)

    def _green_to_middle(self, state, steps):
        g = self.GREEN
        cands = []
        for dx in np.arange(-0.06, 0.0601, 0.01):
            for dy in np.arange(-0.06, 0.0601, 0.01):
                if math.hypot(dx, dy) <= 0.06:
                    cands.append((round(float(MIDDLE[0] + dx), 4), round(float(MIDDLE[1] + dy), 4)))
        cands.sort(key=lambda p: math.hypot(p[0] - MIDDLE[0], p[1] - MIDDLE[1]))
        for p in cands:
            new = _try(state, PutAt(block=g, position=p))
            if new is not None:
                steps.append(PutAt(block=g, position=p))
                return new
        for w in sorted(state.bowls, key=lambda w: float(np.hypot(*(_xy(state, w) - MIDDLE)))):
            if float(np.hypot(*(_xy(state, w) - MIDDLE))) <= self.MID_TOL - 0.015:
                rel = relations(state)
                if any(x == w for _, x in rel.inside):
                    continue  # green would sit on other blocks
                new = _try(state, PutIn(block=g, bowl=w))
                if new is not None:
                    steps.append(PutIn(block=g, bowl=w))
                    return new
        return None


# --------------------------------------------------------------------------- r191
class R191(Intention):
    name = "r191"
    description = (
        "Anything red goes in the bowl furthest to the left. Red means check it, and that's where "
        "I check things."
    )
    RED = "red block"

    @staticmethod
    def _leftmost(state):
        return min(state.bowls, key=lambda w: state.positions[w][0]) if state.bowls else None

    def satisfied(self, state):
        if self.RED not in state.positions:
            return True
        w = self._leftmost(state)
        return w is not None and relations(state).in_bowl(self.RED) == w

    def score(self, state):
        return 1.0 if self.satisfied(state) else 0.0

    def feasible(self, scene):
        return self.RED in scene.objects and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 3), (2, 2))

    def plan(self, state):
        if self.RED not in state.positions:
            return []
        w = self._leftmost(state)
        if w is None:
            return None
        if self.satisfied(state):
            return []
        start, steps = state, []
        state = _clear(state, self.RED, steps)
        if state is None:
            return None
        steps.append(PutIn(block=self.RED, bowl=w))
        return _check(self, start, steps)


# --------------------------------------------------------------------------- r273
class R273(Intention):
    name = "r273"
    description = (
        "Put all the blocks into bowls so nothing's loose. Any bowl is fine, I just don't want "
        "cubes rolling around."
    )

    def satisfied(self, state):
        rel = relations(state)
        return all(rel.in_bowl(b) is not None for b in state.blocks)

    def score(self, state):
        blocks = state.blocks
        if not blocks:
            return 1.0
        rel = relations(state)
        return sum(rel.in_bowl(b) is not None for b in blocks) / len(blocks)

    def feasible(self, scene):
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 3), (1, 2))

    def plan(self, state):
        if not state.bowls:
            return None
        start, steps = state, []
        for _ in range(3 * len(state.blocks) + 5):
            rel = relations(state)
            loose = [b for b in state.blocks if rel.in_bowl(b) is None]
            if not loose:
                break
            b = max(loose, key=lambda b: state.positions[b][2])  # tops first
            counts = {w: sum(1 for _, x in rel.inside if x == w) for w in state.bowls}
            w = min(state.bowls, key=lambda w: (counts[w], float(np.hypot(*(_xy(state, w) - _xy(state, b))))))
            new = _try(state, PutIn(block=b, bowl=w))
            if new is None:
                return None
            steps.append(PutIn(block=b, bowl=w))
            state = new
        return _check(self, start, steps)


# --------------------------------------------------------------------------- sorting into bowls
def _groups_satisfied(state, groups) -> bool:
    rel = relations(state)
    used = []
    for g in groups:
        if not g:
            continue
        bowls = {rel.in_bowl(b) for b in g}
        if len(bowls) != 1 or None in bowls:
            return False
        used.append(bowls.pop())
    return len(set(used)) == len(used)


def _groups_score(state, groups) -> float:
    rel = relations(state)
    total = sum(len(g) for g in groups)
    if total == 0:
        return 1.0
    if _groups_satisfied(state, groups):
        return 1.0
    best = 0
    bowls = state.bowls
    ne = [g for g in groups if g]
    for perm in itertools.permutations(bowls, min(len(ne), len(bowls))):
        best = max(best, sum(rel.in_bowl(b) == w for g, w in zip(ne, perm) for b in g))
    return min(0.99, best / total)


def _groups_plan(state, groups):
    ne = [g for g in groups if g]
    bowls = state.bowls
    if len(bowls) < len(ne):
        return None
    rel = relations(state)
    best, best_key = None, None
    for perm in itertools.permutations(bowls, len(ne)):
        placed = sum(rel.in_bowl(b) == w for g, w in zip(ne, perm) for b in g)
        # blocks of other groups already in a bowl must be taken out of it
        intruders = sum(
            1 for g, w in zip(ne, perm) for h in ne if h is not g for b in h if rel.in_bowl(b) == w
        )
        key = (placed - intruders, -sum(
            float(np.hypot(*(_xy(state, b) - _xy(state, w)))) for g, w in zip(ne, perm) for b in g
        ))
        if best_key is None or key > best_key:
            best, best_key = perm, key
    target = {b: w for g, w in zip(ne, best) for b in g}
    steps = []
    for _ in range(60):
        rel = relations(state)
        wrong = [b for b, w in target.items() if rel.in_bowl(b) != w]
        if not wrong:
            return steps
        # a bowl still holding a misplaced block is emptied of it before anything goes in
        dirty = {rel.in_bowl(b) for b in wrong} - {None}
        movable = [b for b in wrong if rel.above(b) is None and target[b] not in dirty]
        if movable:
            b = max(movable, key=lambda b: state.positions[b][2])
            new = _try(state, PutIn(block=b, bowl=target[b]))
            if new is None:
                return None
            steps.append(PutIn(block=b, bowl=target[b]))
            state = new
            continue
        covered = [b for b in wrong if rel.above(b) is not None]
        stuck = covered or [b for b in wrong if rel.in_bowl(b) is not None]
        if not stuck:
            return None
        chain = _chain_above(state, stuck[0])
        state = _park(state, chain[-1] if chain else stuck[0], steps)
        if state is None:
            return None
    return None


class R335(Intention):
    name = "r335"
    description = "Sort them: plain colours (gray, brown) in one bowl, everything else in another."
    PLAIN = frozenset({"gray", "brown"})

    def _groups(self, names):
        blocks = [n for n in names if n.endswith(" block")]
        return [
            [b for b in blocks if _color(b) in self.PLAIN],
            [b for b in blocks if _color(b) not in self.PLAIN],
        ]

    def satisfied(self, state):
        return _groups_satisfied(state, self._groups(state.positions))

    def score(self, state):
        return _groups_score(state, self._groups(state.positions))

    def feasible(self, scene):
        ne = [g for g in self._groups(scene.objects) if g]
        return len(ne) >= 1 and len(scene.bowls) >= len(ne)

    def sample_scene(self, rng):
        def shows(scene):
            return self.feasible(scene) and all(self._groups(scene.objects))

        return _sample(rng, shows, (2, 3), (2, 2))

    def plan(self, state):
        start = state
        return _check(self, start, _groups_plan(state, self._groups(state.positions)))


class R099(Intention):
    name = "r099"
    description = (
        "Could you put all the warm colours \u2014 red, orange, yellow, pink \u2014 in one bowl and the "
        "cool ones in another? My sister can sort out the browns and grays herself."
    )
    WARM = frozenset({"red", "orange", "yellow", "pink"})
    COOL = frozenset({"blue", "green", "purple", "cyan"})

    def _groups(self, names):
        blocks = [n for n in names if n.endswith(" block")]
        return [
            [b for b in blocks if _color(b) in self.WARM],
            [b for b in blocks if _color(b) in self.COOL],
        ]

    def satisfied(self, state):
        return _groups_satisfied(state, self._groups(state.positions))

    def score(self, state):
        return _groups_score(state, self._groups(state.positions))

    def feasible(self, scene):
        ne = [g for g in self._groups(scene.objects) if g]
        return len(ne) >= 1 and len(scene.bowls) >= len(ne)

    def sample_scene(self, rng):
        def shows(scene):
            return self.feasible(scene) and all(self._groups(scene.objects))

        return _sample(rng, shows, (2, 3), (2, 2))

    def plan(self, state):
        start = state
        return _check(self, start, _groups_plan(state, self._groups(state.positions)))


# --------------------------------------------------------------------------- r177
class R177(Intention):
    name = "r177"
    description = "Leave an empty bowl if you can. I need one empty bowl every morning for the transfer task."

    @staticmethod
    def _counts(state):
        rel = relations(state)
        return {w: sum(1 for _, x in rel.inside if x == w) for w in state.bowls}

    def satisfied(self, state):
        if not state.bowls:
            return True  # no bowl to leave empty: nothing the robot could do
        return min(self._counts(state).values()) == 0

    def score(self, state):
        if not state.bowls:
            return 1.0
        n = len(state.blocks)
        m = min(self._counts(state).values())
        return 1.0 if m == 0 else max(0.0, 1.0 - m / max(1, n))

    def feasible(self, scene):
        return len(scene.bowls) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (2, 3), (1, 2))

    def plan(self, state):
        if self.satisfied(state):
            return []
        start, steps = state, []
        counts = self._counts(state)
        w = min(state.bowls, key=lambda w: (counts[w], state.positions[w][0]))
        rel = relations(state)
        inside = sorted((b for b, x in rel.inside if x == w), key=lambda b: -state.positions[b][2])
        for b in inside:
            state = _park(state, b, steps, prefer=_xy(state, w))
            if state is None:
                return None
        return _check(self, start, steps)


# --------------------------------------------------------------------------- r243
class R243(Intention):
    name = "r243"
    description = (
        "Take whatever bowl is closest to the middle and put blocks around it: one left, one right, "
        "one in front, one behind. Extras stay where they are."
    )

    @staticmethod
    def _bowl(state):
        if not state.bowls:
            return None
        return min(state.bowls, key=lambda w: float(np.hypot(*(_xy(state, w) - MIDDLE))))

    @staticmethod
    def _side_of(state, b, w, strict: bool = False) -> str | None:
        """Which side of bowl w block b stands at, if any (strict: with a margin for noise)."""
        if not _loose_on_table(state, b):
            return None
        v = _xy(state, b) - _xy(state, w)
        lo, hi, off = (0.08, 0.145, 0.04) if strict else (0.07, 0.16, 0.05)
        for side, u in SIDE_UNITS.items():
            u = np.array(u)
            along = float(v @ u)
            perp = abs(float(v[0] * u[1] - v[1] * u[0]))
            if lo <= along <= hi and perp <= off:
                return side
        return None

    def _covered(self, state, strict: bool = False):
        w = self._bowl(state)
        cov: dict[str, str] = {}
        for b in state.blocks:
            s = self._side_of(state, b, w, strict)
            if s is not None and s not in cov:
                cov[s] = b
        return cov

    def satisfied(self, state):
        w = self._bowl(state)
        if w is None:
            return not state.blocks
        return len(self._covered(state)) >= min(4, len(state.blocks))

    def score(self, state):
        w = self._bowl(state)
        if w is None:
            return 0.0
        need = min(4, len(state.blocks))
        return 1.0 if need == 0 else min(1.0, len(self._covered(state)) / need)

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 4

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, 4, 1)

    def plan(self, state):
        w = self._bowl(state)
        if w is None:
            return None
        start, steps = state, []
        wxy = _xy(state, w)
        spots = {s: wxy + NEXT_OFFSET * np.array(u) for s, u in SIDE_UNITS.items()}
        avoid = [tuple(p) for p in spots.values()]
        for _ in range(12):
            cov = self._covered(state, strict=True)
            if len(cov) >= min(4, len(state.blocks)):
                break
            used = set(cov.values())
            free = [b for b in state.blocks if b not in used]
            missing = [s for s in SIDE_UNITS if s not in cov]
            if not free or not missing:
                return None
            # the side whose nearest free block is closest goes first
            s, b = min(
                ((s, b) for s in missing for b in free),
                key=lambda sb: float(np.hypot(*(_xy(state, sb[1]) - spots[sb[0]]))),
            )
            state = _clear(state, b, steps, avoid=avoid)
            if state is None:
                return None
            step = PutNextTo(block=b, target=w, side=s)
            new = _try(state, step)
            if new is None:
                u = np.array(SIDE_UNITS[s])
                perp_u = np.array([-u[1], u[0]])
                for along in (NEXT_OFFSET, 0.11, 0.125, 0.14):
                    for perp in (0.0, 0.02, -0.02, 0.04, -0.04):
                        p = wxy + along * u + perp * perp_u
                        step = PutAt(block=b, position=(float(p[0]), float(p[1])))
                        new = _try(state, step)
                        if new is not None:
                            break
                    if new is not None:
                        break
            if new is None:
                return None
            steps.append(step)
            state = new
        return _check(self, start, steps)


# --------------------------------------------------------------------------- r314
class R314(Intention):
    name = "r314"
    description = "Max three blocks per bowl. Overflow goes next to the bowl, not on top of everything else."
    CAP = 3

    @staticmethod
    def _counts(state):
        rel = relations(state)
        return {w: sum(1 for _, x in rel.inside if x == w) for w in state.bowls}

    def satisfied(self, state):
        return all(c <= self.CAP for c in self._counts(state).values())

    def score(self, state):
        blocks = state.blocks
        if not blocks:
            return 1.0
        over = sum(max(0, c - self.CAP) for c in self._counts(state).values())
        return max(0.0, 1.0 - over / len(blocks))

    def feasible(self, scene):
        return len(scene.bowls) >= 1 and len(scene.blocks) >= 1

    def sample_scene(self, rng):
        return _sample(rng, self.feasible, (3, 4), 1)

    def plan(self, state):
        if self.satisfied(state):
            return []
        start, steps = state, []
        for w in state.bowls:
            for _ in range(12):
                rel = relations(state)
                inside = [b for b, x in rel.inside if x == w]
                if len(inside) <= self.CAP:
                    break
                top = max(inside, key=lambda b: state.positions[b][2])
                step = PutNextTo(block=top, target=w, side="nearest")
                new = _try(state, step)
                if new is None:
                    new = _park(state, top, steps, prefer=_xy(state, w))
                    if new is None:
                        return None
                else:
                    steps.append(step)
                state = new
        return _check(self, start, steps)


ALL = [R048, R081, R095, R152, R191, R252, R273, R335, R099, R177, R243, R314]
