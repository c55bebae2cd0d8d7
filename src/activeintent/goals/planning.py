"""Small placing helpers for planners (free grid points, areas), on the symbolic world model."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from activeintent.memo import memoized
from activeintent.world import BOUNDS, PutAt, Skill, SkillFailure, WorldState, apply_skill

GRID_STEP = 0.06  # spacing of candidate free points (a block is 4 cm wide)


def grid_points(step: float = GRID_STEP) -> list[tuple[float, float]]:
    (x0, x1), (y0, y1) = BOUNDS
    xs = np.arange(x0 + 0.03, x1 - 0.029, step)
    ys = np.arange(y0 + 0.03, y1 - 0.029, step)
    return [(round(float(x), 3), round(float(y), 3)) for y in ys for x in xs]


GRID = grid_points()


def area_points(inside: Callable[[tuple[float, float]], bool], step: float = GRID_STEP) -> list[tuple[float, float]]:
    """Grid points where ``inside`` holds, nearest their centre first (a new list: callers may
    extend it). ``inside``: a region's test on a point, e.g. ``language.REGIONS[name]``."""
    return list(_area_points(inside, step))


@memoized(size=256, why="(an area's test, step): a pure function of a fixed grid (the tests are module-level), asked on every planning step")
def _area_points(inside: Callable[[tuple[float, float]], bool], step: float) -> tuple[tuple[float, float], ...]:
    pts = [p for p in (GRID if step == GRID_STEP else _fine_grid(step)) if inside(p)]
    if not pts:
        return ()
    cx = float(np.mean([p[0] for p in pts]))
    cy = float(np.mean([p[1] for p in pts]))
    return tuple(sorted(pts, key=lambda p: (p[0] - cx) ** 2 + (p[1] - cy) ** 2))


@memoized(size=4, why="a pure function of the grid step")
def _fine_grid(step: float) -> tuple[tuple[float, float], ...]:
    return tuple(grid_points(step))


def area_spots(inside: Callable[[tuple[float, float]], bool]) -> list[tuple[float, float]]:
    """Where a block may be put down in an area: the usual grid points, then (when a bowl or
    other blocks cover those of a small area) the points of a grid twice as fine."""
    coarse = area_points(inside)
    seen = set(coarse)
    return coarse + [p for p in area_points(inside, GRID_STEP / 2) if p not in seen]


def step_ok(state: WorldState, step: Skill) -> WorldState | None:
    """State after ``step``, or None if the step would fail."""
    new, fail = apply_skill(state, step)
    return None if fail is not None else new


def put_free(
    state: WorldState, block: str, points: list[tuple[float, float]]
) -> tuple[WorldState, Skill] | None:
    """Place ``block`` at the first free point of ``points`` (PutAt)."""
    for p in points:
        step = PutAt(block=block, position=p)
        new, fail = apply_skill(state, step)
        if fail is None:
            return new, step
    return None


def nearest_points(state: WorldState, block: str, points: Iterable[tuple[float, float]] = GRID) -> list[tuple[float, float]]:
    """``points`` (default: the grid), nearest ``block`` first."""
    here = state.pos(block)[:2]
    return sorted(points, key=lambda p: (p[0] - here[0]) ** 2 + (p[1] - here[1]) ** 2)


def free_points(state: WorldState, pts: Iterable[tuple[float, float]], b: str, n: int = 6) -> list[Skill]:
    """PutAt skills to the first ``n`` points of ``pts`` (the planner checks they are free)."""
    return [PutAt(block=b, position=p) for p in list(pts)[:n]]


def run(state: WorldState, steps: list[Skill]) -> WorldState | None:
    """Final state of ``steps``, or None if any step fails."""
    for step in steps:
        state, fail = apply_skill(state, step)
        if isinstance(fail, SkillFailure):
            return None
    return state
