"""Symbolic relations of a world state: on, in, next_to, on_table, table position."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel

from activeintent.world.scene import BLOCK_SIZE, BOUNDS, BOWL_INNER_RADIUS, footprint_radius
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


def table_position_name(xy: tuple[float, float] | np.ndarray) -> str:
    """The Code-as-Policies name of a table region: corners, sides or "middle" (3×3 grid)."""
    x, y = float(xy[0]), float(xy[1])
    (x0, x1), (y0, y1) = BOUNDS
    col = min(2, max(0, int((x - x0) / ((x1 - x0) / 3))))
    row = min(2, max(0, int((y1 - y) / ((y1 - y0) / 3))))
    names = [
        ["top left corner", "top side", "top right corner"],
        ["left side", "middle", "right side"],
        ["bottom left corner", "bottom side", "bottom right corner"],
    ]
    return names[row][col]


_MEMO: dict[tuple, Relations] = {}  # planners and judges ask about the same states again and again


def relations(state: WorldState) -> Relations:
    """Compute relations from geometry (centres; blocks are 4 cm cubes). Memoised on the exact
    positions (in order): the result is shared, so callers must not change it."""
    key = tuple(state.positions.items())
    got = _MEMO.get(key)
    if got is None:
        if len(_MEMO) > 50000:
            _MEMO.clear()
        got = _MEMO[key] = _relations(state)
    return got


def _relations(state: WorldState) -> Relations:
    blocks, bowls = state.blocks, state.bowls
    on: list[tuple[str, str]] = []
    inside: list[tuple[str, str]] = []
    for a in blocks:
        pa = state.pos(a)
        for b in blocks:
            if a == b:
                continue
            pb = state.pos(b)
            if np.hypot(*(pa[:2] - pb[:2])) < 0.6 * BLOCK_SIZE and abs(pa[2] - pb[2] - BLOCK_SIZE) < 0.015:
                on.append((a, b))
        for w in bowls:
            pw = state.pos(w)
            if np.hypot(*(pa[:2] - pw[:2])) < BOWL_INNER_RADIUS and pa[2] < 0.25:
                inside.append((a, w))
    in_bowl = {a for a, _ in inside}
    on_table = [a for a in blocks if a not in in_bowl and state.pos(a)[2] < BLOCK_SIZE / 2 + LEVEL_TOL]
    next_to: list[tuple[str, str]] = []
    names = state.names
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            pa, pb = state.pos(a), state.pos(b)
            if state.kind(a) == "bowl" and state.kind(b) == "bowl":
                continue
            if (a, b) in inside or (b, a) in inside or (a, b) in on or (b, a) in on:
                continue
            # Only objects standing on the same surface level are "next to" each other.
            za = 0.0 if state.kind(a) == "bowl" else pa[2] - BLOCK_SIZE / 2
            zb = 0.0 if state.kind(b) == "bowl" else pb[2] - BLOCK_SIZE / 2
            if abs(za - zb) > LEVEL_TOL:
                continue
            if state.kind(a) == "block" and a in in_bowl or state.kind(b) == "block" and b in in_bowl:
                continue
            gap = np.hypot(*(pa[:2] - pb[:2])) - footprint_radius(a) - footprint_radius(b)
            if gap < NEXT_TO_GAP:
                next_to.append(tuple(sorted((a, b))))  # type: ignore[arg-type]
    positions = {n: table_position_name(state.pos(n)[:2]) for n in names}
    return Relations(on=on, inside=inside, next_to=next_to, on_table=on_table, table_position=positions)


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
