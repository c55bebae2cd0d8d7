"""Leaves: one node of the language over a whole group of blocks, with a fixed plan.

The generic planner (planner.py) searches for a plan of any goal. A *recipe* is the short,
deterministic plan of one node for one group — block by block into a bowl, stack onto the
tallest tower, line up beside an anchor — with a few alternatives (``variant``). A
:class:`Leaf` is a node with its parameter, judged on a group by the node itself (holds,
score, moved_ok, static feasibility) and planned by its recipe: the leaves of the bayes grammar
(learners/bayes/hypotheses.py), whose meanings are thereby those of the language.
"""

from __future__ import annotations

from collections.abc import Callable

from activeintent.goals.facts import Facts, facts
from activeintent.goals.nodes import Relation, Structure
from activeintent.goals.planning import area_points, area_spots, nearest_points, put_free
from activeintent.goals.relations import REGIONS
from activeintent.goals.structures import (
    CORNERS,
    Cluster,
    Corners,
    Line,
    OneBowl,
    SeparateBowls,
    Tower,
    TowerOnBlock,
)
from activeintent.world import PutAt, PutIn, PutNextTo, PutOn, Skill, WorldState, apply_skill
from activeintent.world.scene import ROW_PITCH, kind_of

Group = tuple[str, ...]
PlanResult = tuple[WorldState, list[Skill]] | None


class Leaf:
    """A node with its parameter over a group: judge a state, check a scene, plan."""

    variants: int = 1  # how many alternative plans ``plan`` can produce

    def excluded(self) -> str | None:
        """A block the node names, which is therefore not part of the group."""
        return None

    def judge(self, f: Facts, g: Group) -> tuple[bool, float]:
        """(holds, score) of the group in state ``f``."""
        raise NotImplementedError

    def moved_ok(self, fb: Facts, fa: Facts, g: Group, b: str) -> bool:
        """After ``b`` was moved (facts before → after), is its new place consistent with the node?"""
        raise NotImplementedError

    def feasible(self, objects: tuple[str, ...], g: Group) -> bool:
        """Static check: can a scene of ``objects`` show it for the (non-empty) group ``g``?"""
        raise NotImplementedError

    def plan(self, state: WorldState, g: Group, variant: int = 0) -> PlanResult:
        """The state the recipe reaches and its steps, or None when a step fails."""
        raise NotImplementedError


def _turned(g: Group, variant: int) -> list[str]:
    """The group's order, turned by ``variant``: alternative plans visit the blocks in another order."""
    order = list(g)
    if variant and len(order) > 1:
        k = variant % len(order)
        order = order[k:] + order[:k]
    return order


def _block_by_block(state: WorldState, order: list[str], placed: Callable[[Facts, str], bool],
                    target: Callable[[WorldState, str], Skill | None]) -> PlanResult:
    """Each block of ``order`` not yet ``placed``: one step, from the state the steps before left."""
    steps: list[Skill] = []
    for b in order:
        if placed(facts(state), b):
            continue
        step = target(state, b)
        if step is None:
            return None
        state, fail = apply_skill(state, step)
        if fail is not None:
            return None
        steps.append(step)
    return state, steps


def _free_point(state: WorldState, b: str, points: list[tuple[float, float]]) -> Skill | None:
    got = put_free(state, b, points)
    return got[1] if got else None


def flat_down(state: WorldState, g: Group) -> PlanResult:
    """Every block of ``g`` flat on the table: the highest first (so that none stays trapped under
    another), each to the free grid point nearest it."""
    order = sorted(g, key=lambda b: -state.pos(b)[2])
    return _block_by_block(state, order, lambda f, b: f.flat(b), lambda s, b: _free_point(s, b, nearest_points(s, b)))


# ---- every block of the group satisfies a relation --------------------------------------------


class EveryBlock(Leaf):
    """Every block of the group satisfies ``rel:param`` (the language's ``every`` clause).

    Planned block by block in the group's order (turned by the variant), each by one of the
    relation's own target skills: the first, or with ``spread_from`` set the one the variant
    picks, from that variant on also turned by the block's place in the group (alternative plans
    use other bowls, or spread the blocks over them). ``max_group``: the largest group a scene
    can show it for (at most four blocks fit around one object)."""

    def __init__(self, rel: Relation, param: str = "", variants: int = 1, spread_from: int | None = None,
                 max_group: int | None = None):
        self.rel = rel
        self.param = param
        self.variants = variants
        self.spread_from = spread_from
        self.max_group = max_group
        self.ref = rel.refers(param)

    def excluded(self):
        return self.ref if self.ref is not None and kind_of(self.ref) == "block" else None

    def ok(self, f: Facts, b: str) -> bool:
        # a relation naming an object that is not on the table holds for no block (as in Each)
        return (self.ref is None or self.ref in f.pos) and self.rel.ok(f, b, self.param)

    def judge(self, f, g):
        n = sum(self.ok(f, b) for b in g)
        return n == len(g), n / len(g) if g else 1.0

    def moved_ok(self, fb, fa, g, b):
        return self.ok(fa, b)

    def feasible(self, objects, g):
        if self.max_group is not None and len(g) > self.max_group:
            return False
        return (self.ref is None or self.ref in objects) and all(self.rel.possible(b, objects, self.param) for b in g)

    def target(self, state: WorldState, g: Group, b: str, variant: int) -> Skill | None:
        options = self.rel.targets(state, b, self.param)
        if not options:
            return None
        if self.spread_from is None:
            return options[0]
        spread = g.index(b) if variant >= self.spread_from else 0
        return options[(variant + spread) % len(options)]

    def plan(self, state, g, variant=0):
        return _block_by_block(state, _turned(g, variant), lambda f, b: self.ok(f, b),
                               lambda s, b: self.target(s, g, b, variant))


class FlatDown(EveryBlock):
    """Every block flat on the table (``Flat(OnTable())``), planned by :func:`flat_down` (the
    same plan for every variant)."""

    def plan(self, state, g, variant=0):
        return flat_down(state, g)


class IntoArea(EveryBlock):
    """Every block in an area of the table (a region or a cell: the relation's ``area``), each
    put down at the first free spot of the area."""

    def target(self, state, g, b, variant):
        return _free_point(state, b, area_spots(self.rel.area(self.param)))


# ---- the group takes a shape ------------------------------------------------------------------


class Shape(Leaf):
    """The group takes the shape ``struct:param`` (the language's ``form`` clause). ``empty``: the
    verdict on an empty group (a shape of no blocks: vacuously there, unless the leaf says not)."""

    def __init__(self, struct: Structure, param: str = "", variants: int = 1,
                 empty: tuple[bool, float] = (True, 1.0)):
        self.struct = struct
        self.param = param
        self.variants = variants
        self.empty = empty

    def judge(self, f, g):
        return self.struct.judge(f, g, self.param) if g else self.empty

    def moved_ok(self, fb, fa, g, b):
        return self.struct.moved_ok(fb, fa, g, b, self.param)

    def feasible(self, objects, g):
        return self.struct.possible(g, objects, self.param)


class IntoCorners(Shape):
    """Each block in a different corner: block by block, each to a corner no other block of the
    group holds (the coarse grid points of every free corner first, then the fine ones)."""

    struct: Corners

    def target(self, state: WorldState, g: Group, b: str) -> Skill | None:
        f = facts(state)
        taken = {self.struct.corner(f, o) for o in g if o != b}
        free = [c for c in CORNERS if c not in taken]
        for points in (area_points, area_spots):
            for corner in free:
                if got := put_free(state, b, points(REGIONS[corner])):
                    return got[1]
        return None

    def plan(self, state, g, variant=0):
        return _block_by_block(state, _turned(g, variant), lambda f, b: self.struct.block_ok(f, g, b),
                               lambda s, b: self.target(s, g, b))


class Stack(Shape):
    """One tower (``Tower`` in any order, or ``TowerOnBlock``): on the tallest tower the shape can
    grow from (the variant picks another), the other blocks one on top of the other, in the
    group's order (reversed for the variants)."""

    struct: Tower | TowerOnBlock

    def plan(self, state, g, variant=0):
        if not g:
            return state, []
        f = facts(state)
        bases = self.struct.bases(f, g, self.param)
        if not bases:
            return None
        chain = f.tower(bases[variant % len(bases)])
        rest = [b for b in g if b not in chain]
        if variant:
            rest = rest[::-1]
        steps: list[Skill] = []
        top = chain[-1]
        for b in rest:
            step = PutOn(block=b, target=top)
            state, fail = apply_skill(state, step)
            if fail is not None:
                return None
            steps.append(step)
            top = b
        return state, steps


class TwoStacks(Shape):
    """Two towers (``TwoTowersAnyHeights``): the group's first half stacked in order, then the
    second (the variant starts from the other end)."""

    def plan(self, state, g, variant=0):
        order = list(g) if not variant else list(g)[::-1]
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


class LineUp(Shape):
    """A row or column (``Line`` in any order): the others set one beside the next from an anchor
    block, to one side (the variant picks the anchor and side to try first), the highest first;
    failing that, laid out at ROW_PITCH along a free line of points. A lone block: flat down."""

    struct: Line

    def plan(self, state, g, variant=0):
        if len(g) < 2:
            return flat_down(state, g)
        f = facts(state)
        anchors = [b for b in g if f.flat(b)] or list(g)
        tries = [(a, side) for a in anchors for side in self.struct.sides]
        k = variant % len(tries)
        for anchor, side in tries[k:] + tries[:k]:
            order = [anchor] + sorted((o for o in g if o != anchor), key=lambda o: -state.pos(o)[2])
            got = self._lined_up(state, g, [PutNextTo(block=b, target=a, side=side) for a, b in zip(order, order[1:], strict=False)])
            if got is not None:
                return got
        return self._along_points(state, g)

    def _lined_up(self, state: WorldState, g: Group, steps: list[Skill]) -> PlanResult:
        """``steps`` run one after another, when every one succeeds and the line then holds."""
        for step in steps:
            state, fail = apply_skill(state, step)
            if fail is not None:
                return None
        return (state, steps) if self.struct.holds(facts(state), g, self.param) else None

    def _along_points(self, state: WorldState, g: Group) -> PlanResult:
        row = self.struct.axis == 1
        for c in (-0.5, -0.4, -0.6, -0.3, -0.7) if row else (0.0, -0.1, 0.1, -0.2, 0.2):
            for start in (-0.2, -0.1, 0.0) if row else (-0.7, -0.6, -0.5):
                points = [(start + ROW_PITCH * i, c) if row else (c, start + ROW_PITCH * i) for i in range(len(g))]
                got = self._lined_up(state, g, [PutAt(block=b, position=p) for b, p in zip(g, points, strict=True)])
                if got is not None:
                    return got
        return None


class Gather(Shape):
    """Grouped together (``Cluster``): from an anchor block (the variant picks it), each other
    block next to the last placed one it fits beside. A lone block: flat down."""

    struct: Cluster

    def plan(self, state, g, variant=0):
        if len(g) < 2:
            return flat_down(state, g)
        f = facts(state)
        anchors = [b for b in g if f.flat(b)] or list(g)
        anchor = anchors[variant % len(anchors)]
        s, steps = state, []
        placed = [anchor]
        for b in [o for o in g if o != anchor]:
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


class IntoOneBowl(Shape):
    """All in one bowl (``OneBowl``): the bowl holding most of the group (the variant picks the
    next), the others put in it."""

    struct: OneBowl

    def plan(self, state, g, variant=0):
        if not state.bowls:
            return None
        f = facts(state)
        counts: dict[str, int] = {}
        for b in g:
            if (w := f.bowl_of[b]) is not None:
                counts[w] = counts.get(w, 0) + 1
        bowl = sorted(state.bowls, key=lambda w: -counts.get(w, 0))[variant % len(state.bowls)]
        return _block_by_block(state, list(g), lambda f, b: f.bowl_of[b] == bowl, lambda s, b: PutIn(block=b, bowl=bowl))


class OnePerBowl(Shape):
    """One block per bowl (``SeparateBowls``): block by block, each misplaced one into the first
    bowl no other block of the group is in (the variant goes through the bowls backwards)."""

    struct: SeparateBowls

    def target(self, state: WorldState, g: Group, b: str, bowls: list[str]) -> Skill | None:
        f = facts(state)
        used = {f.bowl_of[o] for o in g if o != b}
        free = [w for w in bowls if w not in used]
        return PutIn(block=b, bowl=free[0]) if free else None

    def plan(self, state, g, variant=0):
        bowls = list(state.bowls)[::-1] if variant else list(state.bowls)
        return _block_by_block(state, list(g), lambda f, b: self.struct.block_ok(f, g, b),
                               lambda s, b: self.target(s, g, b, bowls))
