"""One generic planner for every goal of the language, on the symbolic world model.

Search over the robot's skills by hill climbing on the goal's own measure of progress
``(number of clauses that hold, mean clause score)``: at every step the first move that
improves it is taken. Moves are tried in this order:

1. the moves the goal's node types suggest (``Relation.targets``, ``Structure.suggest``),
2. every generic move: each movable block into each bowl, onto each clear block, at each side
   of each object, and at grid points of each table region.

When nothing improves, up to two *neutral* moves (a block set down on a free table point
without making things worse) free a covered block or clear a spot. Every move is checked by
``world.apply_skill``; the plan is returned only if the final state satisfies the goal, so a
returned plan is always correct on the world model. The search is bounded by a count of tried
moves (deterministic, no clock), so "infeasible" means "not found within the budget".
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from activeintent.goals.facts import Facts, facts
from activeintent.goals.goal import Goal
from activeintent.goals.relations import REGIONS, region_points
from activeintent.memo import BoundedCache
from activeintent.world import (
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    Skill,
    WorldState,
    apply_skill,
    layout,
)
from activeintent.world.skills import SIDES, skill_key

REGION_SPOTS = tuple(dict.fromkeys(p for r in REGIONS for p in region_points(r)[:1]))
MAX_TRIES = 600  # candidate moves tried per plan


def value(goal: Goal, f: Facts) -> tuple[int, float]:
    return goal.value(f)


def generic_moves(state: WorldState, f: Facts, blocks: list[str]) -> Iterator[Skill]:
    """Every place a block can be put: bowls, block tops, sides of objects, region spots."""
    for b in blocks:
        for w in state.bowls:
            yield PutIn(block=b, bowl=w)
        for o in state.blocks:
            if o != b and f.clear(o):
                yield PutOn(block=b, target=o)
        for o in state.names:
            if o != b:
                for s in SIDES:
                    yield PutNextTo(block=b, target=o, side=s)
        for p in REGION_SPOTS:
            yield PutAt(block=b, position=p)


def _try(state: WorldState, step: Skill) -> WorldState | None:
    new, fail = apply_skill(state, step)
    if fail is not None or new.positions == state.positions:
        return None
    return new


def plan(goal: Goal, state: WorldState, variant: int = 0, max_tries: int = MAX_TRIES) -> list[Skill] | None:
    """A plan that makes ``goal`` hold from ``state`` (``[]`` if it already does), or None.
    ``variant`` > 0 shuffles the order in which moves are tried (an alternative plan)."""
    rng = np.random.default_rng(variant) if variant else None
    f = facts(state)
    movable = sorted(goal.groups(f)) if goal.stays else list(state.blocks)
    steps: list[Skill] = []
    tries, neutral = 0, 0
    for _ in range(3 * len(state.blocks) + 4):
        f = facts(state)
        if goal.holds(f):
            return steps
        v = value(goal, f)
        suggested = [s for c in goal.clauses if not c.holds(f) for s in c.suggest(state, f)]
        if rng is not None:
            suggested = [suggested[i] for i in rng.permutation(len(suggested))]
        unhappy = [b for c in goal.clauses if not c.holds(f) for b in c.group_f(f)]
        order = list(dict.fromkeys([b for b in unhappy if b in movable] + movable))
        if rng is not None:
            order = [order[i] for i in rng.permutation(len(order))]
        found = None
        fallback: tuple[WorldState, Skill] | None = None
        for step in _chain(suggested, generic_moves(state, f, order)):
            if step.block not in movable:
                continue
            tries += 1
            if tries > max_tries:
                return None
            new = _try(state, step)
            if new is None:
                continue
            vn = value(goal, facts(new))
            if vn > v and (vn[0] > v[0] or vn[1] > v[1] + 1e-9):
                found = (new, step)
                break
            if fallback is None and vn >= v and isinstance(step, PutAt | PutNextTo) and step.block in unhappy:
                fallback = (new, step)
        if found is None:
            if fallback is None or neutral >= 2:
                return None
            neutral += 1
            found = fallback
        state = found[0]
        steps.append(found[1])
    return steps if goal.holds(facts(state)) else None


def _chain(first: list[Skill], rest: Iterator[Skill]) -> Iterator[Skill]:
    seen = set()
    for s in first:
        k = skill_key(s)
        if k not in seen:
            seen.add(k)
            yield s
    for s in rest:
        k = skill_key(s)
        if k not in seen:
            seen.add(k)
            yield s


def run(state: WorldState, steps: list[Skill]) -> WorldState | None:
    for step in steps:
        state, fail = apply_skill(state, step)
        if fail is not None:
            return None
    return state


# by (goal, scene objects): a pure function of them (the layout is fixed by LAYOUT_SEED)
_FEASIBLE: BoundedCache[tuple[str, tuple[str, ...]], bool] = BoundedCache(200_000)
LAYOUT_SEED = 0


def feasible(goal: Goal, scene: Scene) -> bool:
    """The planner finds a plan on the scene's layout (seed ``LAYOUT_SEED``); cached."""
    return _FEASIBLE.get_or_make((goal.key, tuple(scene.objects)), lambda: goal.possible(tuple(scene.objects)) and plan(
        goal, WorldState(positions=layout(scene, LAYOUT_SEED))) is not None)
