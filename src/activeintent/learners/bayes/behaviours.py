"""What a group of blocks should do: the leaves of the hypothesis grammar.

A behaviour is either a per-block rule ("every block goes in the bowl of its own colour")
or a structure over the whole group ("the blocks form one tower"). Each can judge a state
(``holds``, graded ``score``, ``ok`` for one block's placement), say whether a scene lets it
be shown (``feasible``), and plan it on the symbolic world model (``plan``).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

from activeintent.goals.facts import ALIGN_TOL, Facts, facts
from activeintent.goals.planning import (
    HALVES,
    in_region,
    nearest_points,
    put_free,
    region_points,
    region_spots,
)
from activeintent.world import PutAt, PutIn, PutNextTo, PutOn, Skill, WorldState, apply_skill
from activeintent.world.scene import color_of

Group = tuple[str, ...]
ROW_PITCH = 0.052  # centre spacing of blocks set next to each other (world.predict)
MIN_SPACING = 0.03
PlanResult = tuple[WorldState, list[Skill]] | None


def _own_bowl(block: str) -> str:
    return f"{color_of(block)} bowl"


class Behaviour:
    """Base: a per-block rule; structures override ``holds``/``ok``/``score``/``plan``."""

    family: str = ""
    param: str | None = None
    variants: int = 1  # how many alternative plans ``plan`` can produce

    def phrase(self, subject: str) -> str:
        raise NotImplementedError

    def excluded(self) -> str | None:
        """A block the rule refers to, which is therefore not part of the group."""
        return None

    def ok(self, f: Facts, group: Group, b: str) -> bool:
        raise NotImplementedError

    def holds(self, f: Facts, group: Group) -> bool:
        return all(self.ok(f, group, b) for b in group)

    def moved_ok(self, fb: Facts, fa: Facts, group: Group, b: str) -> bool:
        """After ``b`` was moved (facts before → after), is its new place consistent with z?"""
        return self.ok(fa, group, b)

    def score(self, f: Facts, group: Group) -> float:
        return sum(self.ok(f, group, b) for b in group) / len(group) if group else 1.0

    def feasible(self, objects: tuple[str, ...], group: Group) -> bool:
        return True

    def target(self, state: WorldState, group: Group, b: str, variant: int) -> Skill | None:
        raise NotImplementedError

    def plan(self, state: WorldState, group: Group, variant: int = 0) -> PlanResult:
        steps: list[Skill] = []
        order = list(group)
        if variant and len(order) > 1:  # alternative plans visit the blocks in another order
            k = variant % len(order)
            order = order[k:] + order[:k]
        for b in order:
            if self.ok(facts(state), group, b):
                continue
            step = self.target(state, group, b, variant)
            if step is None:
                return None
            state, fail = apply_skill(state, step)
            if fail is not None:
                return None
            steps.append(step)
        return state, steps

    @property
    def key(self) -> str:
        return self.family + (f"[{self.param}]" if self.param else "")


# ---- per-block rules -------------------------------------------------------------------


class InSameBowl(Behaviour):
    family = "in-same-bowl"

    def phrase(self, s: str) -> str:
        return f"{s} go in the bowl of their own colour"

    def ok(self, f, group, b):
        return f.bowl_of[b] == _own_bowl(b)

    def feasible(self, objects, group):
        return all(_own_bowl(b) in objects for b in group)

    def target(self, state, group, b, variant):
        return PutIn(block=b, bowl=_own_bowl(b))


class InOtherBowl(Behaviour):
    family = "in-other-bowl"
    variants = 3

    def phrase(self, s: str) -> str:
        return f"{s} go in a bowl of a different colour"

    def ok(self, f, group, b):
        w = f.bowl_of[b]
        return w is not None and color_of(w) != color_of(b)

    def feasible(self, objects, group):
        bowls = [o for o in objects if o.endswith(" bowl")]
        return all(any(color_of(w) != color_of(b) for w in bowls) for b in group)

    def target(self, state, group, b, variant):
        bowls = [w for w in state.bowls if color_of(w) != color_of(b)]
        if not bowls:
            return None
        spread = group.index(b) if variant > 1 else 0  # variant 2 spreads blocks over bowls
        return PutIn(block=b, bowl=bowls[(variant + spread) % len(bowls)])


class InAnyBowl(Behaviour):
    family = "in-any-bowl"
    variants = 3

    def phrase(self, s: str) -> str:
        return f"{s} go in bowls (any bowl)"

    def ok(self, f, group, b):
        return f.bowl_of[b] is not None

    def feasible(self, objects, group):
        return any(o.endswith(" bowl") for o in objects)

    def target(self, state, group, b, variant):
        bowls = state.bowls
        return PutIn(block=b, bowl=bowls[(variant + group.index(b)) % len(bowls)]) if bowls else None


@dataclass
class InBowl(Behaviour):
    param: str = "red"
    family = "in-bowl"

    def phrase(self, s: str) -> str:
        return f"{s} go in the {self.param} bowl"

    def ok(self, f, group, b):
        return f.bowl_of[b] == f"{self.param} bowl"

    def feasible(self, objects, group):
        return f"{self.param} bowl" in objects

    def target(self, state, group, b, variant):
        return PutIn(block=b, bowl=f"{self.param} bowl")


class OnTable(Behaviour):
    family = "on-table"

    def phrase(self, s: str) -> str:
        return f"{s} stay flat on the table (not in bowls, not stacked)"

    def ok(self, f, group, b):
        return f.flat(b)

    def target(self, state, group, b, variant):
        got = put_free(state, b, nearest_points(state, b))
        return got[1] if got else None

    def plan(self, state, group, variant=0):
        # Take the highest blocks down first, so that no block is trapped under another.
        order = sorted(group, key=lambda b: -state.pos(b)[2])
        return Behaviour.plan(self, state, tuple(order), 0)


class NextToSameBowl(Behaviour):
    family = "next-to-same-bowl"

    def phrase(self, s: str) -> str:
        return f"{s} go on the table next to the bowl of their own colour"

    def ok(self, f, group, b):
        return f.next_to(b, _own_bowl(b)) and f.flat(b)

    def feasible(self, objects, group):
        return all(_own_bowl(b) in objects for b in group)

    def target(self, state, group, b, variant):
        return PutNextTo(block=b, target=_own_bowl(b))


@dataclass
class NextToBowl(Behaviour):
    param: str = "red"
    family = "next-to-bowl"

    def phrase(self, s: str) -> str:
        return f"{s} go on the table next to the {self.param} bowl"

    def ok(self, f, group, b):
        return f.next_to(b, f"{self.param} bowl") and f.flat(b)

    def feasible(self, objects, group):
        return f"{self.param} bowl" in objects and len(group) <= 4

    def target(self, state, group, b, variant):
        return PutNextTo(block=b, target=f"{self.param} bowl")


@dataclass
class NextToBlock(Behaviour):
    param: str = "red"
    family = "next-to-block"

    def phrase(self, s: str) -> str:
        return f"{s} go on the table next to the {self.param} block"

    def excluded(self):
        return f"{self.param} block"

    def ok(self, f, group, b):
        return f.next_to(b, f"{self.param} block") and f.flat(b)

    def feasible(self, objects, group):
        return f"{self.param} block" in objects and 1 <= len(group) <= 4

    def target(self, state, group, b, variant):
        return PutNextTo(block=b, target=f"{self.param} block")


@dataclass
class InRegion(Behaviour):
    param: str = "middle"
    family = "region"

    def phrase(self, s: str) -> str:
        where = self.param if self.param.endswith("half") else f"{self.param}"
        return f"{s} go to the {where} of the table (not in bowls)"

    def ok(self, f, group, b):
        if b not in f.on_table or f.below[b] is not None:
            return False
        return in_region(self.param, f.xy[b]) if self.param in HALVES else f.cell[b] == self.param

    def target(self, state, group, b, variant):
        got = put_free(state, b, region_spots(self.param))
        return got[1] if got else None


class DistinctCorners(Behaviour):
    family = "distinct-corners"
    corners = ("top left corner", "top right corner", "bottom left corner", "bottom right corner")

    def phrase(self, s: str) -> str:
        return f"{s} go on the table, each in a different corner of the table"

    def _corner(self, f: Facts, b: str) -> str | None:
        ok = b in f.on_table and f.below[b] is None and f.cell[b] in self.corners
        return f.cell[b] if ok else None

    def ok(self, f, group, b):
        mine = self._corner(f, b)
        return mine is not None and all(self._corner(f, o) != mine for o in group if o != b)

    def feasible(self, objects, group):
        return len(group) <= 4

    def target(self, state, group, b, variant):
        f = facts(state)
        taken = {self._corner(f, o) for o in group if o != b}
        free = [c for c in self.corners if c not in taken]
        for points in (region_points, region_spots):  # the fine points only once no corner has a coarse one
            for corner in free:
                if got := put_free(state, b, points(corner)):
                    return got[1]
        return None


# ---- structures over the group ---------------------------------------------------------


def _towers(f: Facts, group: Group, table_only: bool = False) -> list[list[str]]:
    """Towers built from group blocks only (single blocks count as height 1); with
    ``table_only`` only those standing on the table (not in a bowl)."""
    gs = set(group)
    out = []
    for b in group:
        if f.below[b] is None and (not table_only or b in f.on_table):
            chain = f.tower(b)
            if all(c in gs for c in chain):
                out.append(chain)
    return out


class Tower(Behaviour):
    family = "tower"
    variants = 3

    def __init__(self, table_only: bool = True):
        self.table_only = table_only  # a tower stands on the table: a pile in a bowl is none

    def phrase(self, s: str) -> str:
        return f"{s} are stacked into one tower"

    def moved_ok(self, fb: Facts, fa: Facts, group: Group, b: str) -> bool:
        # Building a tower only ever puts blocks on blocks.
        return fa.below[b] is not None or (len(group) == 1 and self.ok(fa, group, b))

    def base_ok(self, base: str) -> bool:
        return True

    def holds(self, f, group):
        if not group:
            return True
        towers = [t for t in _towers(f, group, self.table_only) if len(t) == len(group)]
        return bool(towers) and self.base_ok(towers[0][0])

    def ok(self, f, group, b):
        if len(group) == 1:
            return f.flat(b)
        towers = [t for t in _towers(f, group, self.table_only) if self.base_ok(t[0]) or len(t) == 1]
        best = max((len(t) for t in towers), default=0)
        return best >= 2 and any(b in t and len(t) == best for t in towers)

    def score(self, f, group):
        if not group:
            return 1.0
        towers = [t for t in _towers(f, group, self.table_only) if self.base_ok(t[0]) or len(t) == 1]
        return max((len(t) for t in towers), default=0) / len(group)

    def bases(self, state: WorldState, group: Group) -> list[str]:
        f = facts(state)
        towers = sorted(_towers(f, group, self.table_only), key=len, reverse=True)
        return [t[0] for t in towers if self.base_ok(t[0])]

    def plan(self, state, group, variant=0):
        if not group:
            return state, []
        bases = self.bases(state, group)
        if not bases:
            return None
        base = bases[variant % len(bases)]
        f = facts(state)
        chain = f.tower(base)
        steps: list[Skill] = []
        rest = [b for b in group if b not in chain]
        if variant:
            rest = rest[::-1]
        top = chain[-1]
        for b in rest:
            step = PutOn(block=b, target=top)
            state, fail = apply_skill(state, step)
            if fail is not None:
                return None
            steps.append(step)
            top = b
        return state, steps


class TowerOn(Tower):
    family = "tower-on"
    variants = 2

    def __init__(self, param: str = "red"):
        super().__init__(False)
        self.param = param

    def phrase(self, s: str) -> str:
        return f"{s} are stacked into one tower on the {self.param} block"

    def base_ok(self, base):
        return base == f"{self.param} block"

    def feasible(self, objects, group):
        return f"{self.param} block" in group and len(group) >= 2


class TwoTowers(Behaviour):
    family = "two-towers"
    variants = 2

    def phrase(self, s: str) -> str:
        return f"{s} are stacked into two towers"

    def holds(self, f, group):
        towers = _towers(f, group, table_only=True)
        return len(towers) == 2 and all(len(t) >= 2 for t in towers) and sum(map(len, towers)) == len(group)

    def ok(self, f, group, b):
        towers = sorted(_towers(f, group, table_only=True), key=len, reverse=True)
        return any(b in t for t in towers[:2] if len(t) >= 2)

    def feasible(self, objects, group):
        return len(group) >= 4

    def plan(self, state, group, variant=0):
        order = list(group) if not variant else list(group)[::-1]
        half = (len(order) + 1) // 2
        steps: list[Skill] = []
        for part in (order[:half], order[half:]):
            for lower, upper in zip(part, part[1:], strict=False):
                step = PutOn(block=upper, target=lower)
                state, fail = apply_skill(state, step)
                if fail is not None:
                    return None
                steps.append(step)
        return state, steps


class Line(Behaviour):
    """Row (left-right, same y) or column (front-back, same x) of flat blocks, each next to
    its neighbour along the line."""

    axis = 1  # coordinate that must agree: 1 = y (a row)
    sides = ("right", "left")

    def _line(self, f: Facts, blocks) -> bool:
        if not blocks:
            return True
        if not all(f.flat(b) for b in blocks):
            return False
        across = [f.xy[b][self.axis] for b in blocks]
        if max(across) - min(across) > ALIGN_TOL:
            return False
        along = sorted(blocks, key=lambda b: f.xy[b][1 - self.axis])
        return all(
            f.xy[b][1 - self.axis] - f.xy[a][1 - self.axis] >= MIN_SPACING and f.next_to(a, b)
            for a, b in zip(along, along[1:], strict=False)
        )

    def holds(self, f, group):
        return self._line(f, group)

    def ok(self, f, group, b):
        return f.flat(b) and (len(group) == 1 or any(self._line(f, (b, o)) for o in group if o != b))

    def moved_ok(self, fb, fa, group, b):
        # Set beside blocks but in line with none of them moves away; alone on the table is fine.
        if not fa.flat(b):
            return False
        v = fa.xy[b][self.axis]
        near = [o for o in fa.blocks if o != b and fa.flat(o) and fa.next_to(b, o)]
        return not near or any(abs(fa.xy[o][self.axis] - v) <= ALIGN_TOL for o in near)

    def score(self, f, group):
        if not group:
            return 1.0
        flat = [b for b in group if f.flat(b)]
        for size in range(len(flat), 1, -1):
            if any(self._line(f, c) for c in combinations(flat, size)):
                return size / len(group)
        return min(1, len(flat)) / len(group)

    def plan(self, state, group, variant=0):
        if len(group) < 2:
            return OnTable().plan(state, group)
        f = facts(state)
        anchors = [b for b in group if f.flat(b)] or list(group)
        tries = [(a, side) for a in anchors for side in self.sides]
        k = variant % len(tries)
        for anchor, side in tries[k:] + tries[:k]:
            s, steps, prev = state, [], anchor
            for b in sorted((g for g in group if g != anchor), key=lambda g: -state.pos(g)[2]):
                step = PutNextTo(block=b, target=prev, side=side)
                s, fail = apply_skill(s, step)
                if fail is not None:
                    break
                steps.append(step)
                prev = b
            else:
                if self.holds(facts(s), group):
                    return s, steps
        return self._plan_points(state, group)

    def _plan_points(self, state, group):
        # Fallback: lay the blocks out at ROW_PITCH on a free line of points.
        for c in (-0.5, -0.4, -0.6, -0.3, -0.7) if self.axis == 1 else (0.0, -0.1, 0.1, -0.2, 0.2):
            for start in (-0.2, -0.1, 0.0) if self.axis == 1 else (-0.7, -0.6, -0.5):
                s, steps = state, []
                for i, b in enumerate(group):
                    p = (start + ROW_PITCH * i, c) if self.axis == 1 else (c, start + ROW_PITCH * i)
                    step = PutAt(block=b, position=p)
                    s, fail = apply_skill(s, step)
                    if fail is not None:
                        break
                    steps.append(step)
                else:
                    if self.holds(facts(s), group):
                        return s, steps
        return None


class Row(Line):
    family = "row"
    axis = 1
    sides = ("right", "left")
    variants = 3

    def phrase(self, s: str) -> str:
        return f"{s} are aligned horizontally in one left-right row on the table"


class Column(Line):
    family = "column"
    axis = 0
    sides = ("behind", "front")
    variants = 3

    def phrase(self, s: str) -> str:
        return f"{s} are aligned vertically in one front-back column on the table"


class Cluster(Behaviour):
    family = "cluster"
    variants = 2

    def phrase(self, s: str) -> str:
        return f"{s} are grouped together on the table, each touching another"

    def _component(self, f, group, start):
        seen, todo = {start}, [start]
        while todo:
            a = todo.pop()
            for o in group:
                if o not in seen and f.flat(o) and f.next_to(a, o):
                    seen.add(o)
                    todo.append(o)
        return seen

    def holds(self, f, group):
        if not all(f.flat(b) for b in group):
            return False
        return len(group) < 2 or len(self._component(f, group, group[0])) == len(group)

    def ok(self, f, group, b):
        if not f.flat(b):
            return False
        return len(group) == 1 or any(o != b and f.flat(o) and f.next_to(b, o) for o in group)

    def score(self, f, group):
        if not group:
            return 1.0
        best = max((len(self._component(f, group, b)) for b in group if f.flat(b)), default=0)
        return best / len(group)

    def plan(self, state, group, variant=0):
        if len(group) < 2:
            return OnTable().plan(state, group)
        f = facts(state)
        anchors = [b for b in group if f.flat(b)] or list(group)
        anchor = anchors[variant % len(anchors)]
        s, steps = state, []
        placed = [anchor]
        for b in [g for g in group if g != anchor]:
            for target in placed[::-1]:
                step = PutNextTo(block=b, target=target)
                new, fail = apply_skill(s, step)
                if fail is None:
                    s = new
                    steps.append(step)
                    placed.append(b)
                    break
            else:
                return None
        return s, steps


class OneBowl(Behaviour):
    family = "one-bowl"
    variants = 3

    def phrase(self, s: str) -> str:
        return f"{s} all go in one bowl together"

    def _main(self, f, group):
        counts: dict[str, int] = {}
        for b in group:
            if (w := f.bowl_of[b]) is not None:
                counts[w] = counts.get(w, 0) + 1
        return counts

    def holds(self, f, group):
        return bool(group) and f.bowl_of[group[0]] is not None and all(
            f.bowl_of[b] == f.bowl_of[group[0]] for b in group
        )

    def ok(self, f, group, b):
        counts = self._main(f, group)
        w = f.bowl_of[b]
        return w is not None and counts[w] == max(counts.values())

    def score(self, f, group):
        counts = self._main(f, group)
        return max(counts.values(), default=0) / len(group) if group else 1.0

    def feasible(self, objects, group):
        return any(o.endswith(" bowl") for o in objects)

    def plan(self, state, group, variant=0):
        if not state.bowls:
            return None
        counts = self._main(facts(state), group)
        bowls = sorted(state.bowls, key=lambda w: -counts.get(w, 0))
        bowl = bowls[variant % len(bowls)]
        steps: list[Skill] = []
        for b in group:
            if facts(state).bowl_of[b] == bowl:
                continue
            step = PutIn(block=b, bowl=bowl)
            state, fail = apply_skill(state, step)
            if fail is not None:
                return None
            steps.append(step)
        return state, steps


class DistinctBowls(Behaviour):
    family = "distinct-bowls"
    variants = 2

    def phrase(self, s: str) -> str:
        return f"{s} go in bowls, one block per bowl"

    def ok(self, f, group, b):
        w = f.bowl_of[b]
        return w is not None and not any(o != b and f.bowl_of[o] == w for o in group)

    def feasible(self, objects, group):
        return sum(o.endswith(" bowl") for o in objects) >= len(group)

    def plan(self, state, group, variant=0):
        bowls = list(state.bowls)
        if variant:
            bowls = bowls[::-1]
        steps: list[Skill] = []
        for b in group:
            f = facts(state)
            if self.ok(f, group, b):
                continue
            used = {f.bowl_of[o] for o in group if o != b}
            free = [w for w in bowls if w not in used]
            if not free:
                return None
            step = PutIn(block=b, bowl=free[0])
            state, fail = apply_skill(state, step)
            if fail is not None:
                return None
            steps.append(step)
        return state, steps
