"""Symbolic relations of a world state: on, in, next_to, on_table, table position."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel

from activeintent.memo import BoundedCache
from activeintent.world.scene import (
    BLOCK_SIZE,
    BOUNDS,
    BOWL_INNER_RADIUS,
    footprint_radius,
    kind_of,
)
from activeintent.world.state import WorldState

NEXT_TO_GAP = 0.05  # footprints closer than this (m) count as next to each other
LEVEL_TOL = 0.012


class Relations(BaseModel):
    on: list[tuple[str, str]]  # (upper block, lower block): directly on top
    inside: list[tuple[str, str]]  # (block, bowl)
    next_to: list[tuple[str, str]]  # symmetric pairs, each listed once (sorted)
    on_table: list[str]  # blocks resting on the table, not in a bowl
    table_position: dict[str, str]

    def in_bowl(self, block: str) -> str | None:
        return next((b for a, b in self.inside if a == block), None)

    def below(self, block: str) -> str | None:
        return next((b for a, b in self.on if a == block), None)

    def above(self, block: str) -> str | None:
        return next((a for a, b in self.on if b == block), None)

    def is_next_to(self, a: str, b: str) -> bool:
        return tuple(sorted((a, b))) in {tuple(p) for p in self.next_to}


_GRID = (
    ("top left corner", "top side", "top right corner"),
    ("left side", "middle", "right side"),
    ("bottom left corner", "bottom side", "bottom right corner"),
)


def table_position_name(xy: tuple[float, float] | np.ndarray) -> str:
    """The Code-as-Policies name of a table region: corners, sides or "middle" (3×3 grid)."""
    x, y = float(xy[0]), float(xy[1])
    (x0, x1), (y0, y1) = BOUNDS
    col = min(2, max(0, int((x - x0) / ((x1 - x0) / 3))))
    row = min(2, max(0, int((y1 - y) / ((y1 - y0) / 3))))
    return _GRID[row][col]


# planners and judges ask about the same states again and again; by exact positions in order
_MEMO: BoundedCache[tuple, Relations] = BoundedCache(50000)


def relations(state: WorldState) -> Relations:
    """Compute relations from geometry (centres; blocks are 4 cm cubes). Memoised on the exact
    positions (in order): the result is shared, so callers must not change it."""
    return _MEMO.get_or_make(tuple(state.positions.items()), lambda: _relations(state))


def _relations(state: WorldState) -> Relations:
    # Plain floats and precomputed kinds (the same IEEE arithmetic as on numpy arrays): this
    # runs for every state a planner tries.
    pos = state.positions
    kind = {n: kind_of(n) for n in pos}
    radius = {n: footprint_radius(n) for n in pos}
    blocks = [n for n in pos if kind[n] == "block"]
    bowls = [n for n in pos if kind[n] == "bowl"]
    on: list[tuple[str, str]] = []
    inside: list[tuple[str, str]] = []
    for a in blocks:
        ax, ay, az = pos[a]
        for b in blocks:
            if a == b:
                continue
            bx, by, bz = pos[b]
            if np.hypot(ax - bx, ay - by) < 0.6 * BLOCK_SIZE and abs(az - bz - BLOCK_SIZE) < 0.015:
                on.append((a, b))
        for w in bowls:
            wx, wy, _ = pos[w]
            if np.hypot(ax - wx, ay - wy) < BOWL_INNER_RADIUS and az < 0.25:
                inside.append((a, w))
    in_bowl = {a for a, _ in inside}
    on_table = [a for a in blocks if a not in in_bowl and pos[a][2] < BLOCK_SIZE / 2 + LEVEL_TOL]
    touching = set(inside) | set(on)
    next_to: list[tuple[str, str]] = []
    names = list(pos)
    for i, a in enumerate(names):
        ax, ay, az = pos[a]
        for b in names[i + 1 :]:
            if kind[a] == "bowl" and kind[b] == "bowl":
                continue
            if (a, b) in touching or (b, a) in touching:
                continue
            bx, by, bz = pos[b]
            # Only objects standing on the same surface level are "next to" each other.
            za = 0.0 if kind[a] == "bowl" else az - BLOCK_SIZE / 2
            zb = 0.0 if kind[b] == "bowl" else bz - BLOCK_SIZE / 2
            if abs(za - zb) > LEVEL_TOL:
                continue
            if kind[a] == "block" and a in in_bowl or kind[b] == "block" and b in in_bowl:
                continue
            gap = np.hypot(ax - bx, ay - by) - radius[a] - radius[b]
            if gap < NEXT_TO_GAP:
                next_to.append(tuple(sorted((a, b))))  # type: ignore[arg-type]
    positions = {n: table_position_name(pos[n]) for n in names}
    # built as is: every field is already of its type (validation took a fifth of its time)
    return Relations.model_construct(on=on, inside=inside, next_to=next_to, on_table=on_table, table_position=positions)


def describe_state(state: WorldState, rel: Relations | None = None) -> str:
    """One paragraph in plain English, for text-only models."""
    rel = rel or relations(state)
    parts: list[str] = []
    for b in state.blocks:
        if (bowl := rel.in_bowl(b)) and not rel.below(b):
            parts.append(f"the {b} is in the {bowl}")
        elif below := rel.below(b):
            parts.append(f"the {b} is on the {below}" + (f" (in the {rel.in_bowl(b)})" if rel.in_bowl(b) else ""))
        elif b in rel.on_table:
            parts.append(f"the {b} is on the table at the {rel.table_position[b]}")
        else:
            parts.append(f"the {b} is at the {rel.table_position[b]}")
    for w in state.bowls:
        parts.append(f"the {w} is at the {rel.table_position[w]}")
    pairs = [f"the {a} is next to the {b}" for a, b in rel.next_to]
    text = "; ".join(parts)
    if pairs:
        text += ". Also, " + "; ".join(pairs)
    return text[0].upper() + text[1:] + "." if text else "The table is empty."
