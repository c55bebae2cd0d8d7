"""φ(s): features of one world state for linear reward learning, r(s) = w · φ(s).

Defined once, in general, from the world's relations (``world.relations`` via
``learners.bayes.facts``), without looking at any suite's intentions:

- for every block class — all blocks, the warm and the cool ones (``world.colors``), and
  each of the ten colours — and every relation kind of one block, the fraction of the class's
  blocks in that relation (0 when the scene has no block of the class);
- a few global counts, each normalised to [0, 1].

Relation kinds of one block: in a bowl, in the bowl of its own colour, in a bowl of another
colour, on a block, under a block, flat on the table, next to a block, next to a bowl, next to
its own-colour bowl, next to a bowl of another colour, in each of the nine table regions
(``world.relations.table_position_name``), part of a left-right row, of a front-back column,
of a tower, of a touching group of blocks.
"""

from __future__ import annotations

import numpy as np

from activeintent.goals.facts import ALIGN_TOL, Facts, facts
from activeintent.memo import memoized
from activeintent.world import WorldState
from activeintent.world.colors import COLOR_NAMES, COOL_COLORS, WARM_COLORS
from activeintent.world.relations import _GRID
from activeintent.world.scene import color_of, kind_of

CLASSES: tuple[str, ...] = ("all", "warm", "cool", *COLOR_NAMES)
REGIONS: tuple[str, ...] = tuple(name for row in _GRID for name in row)
RELATIONS: tuple[str, ...] = (
    "in-bowl", "in-own-colour-bowl", "in-other-colour-bowl", "on-block", "under-block", "flat",
    "beside-block", "beside-bowl", "beside-own-colour-bowl", "beside-other-colour-bowl",
    *(f"region[{r}]" for r in REGIONS),
    "part-of-row", "part-of-column", "part-of-tower", "part-of-touching-group",
)
GLOBALS: tuple[str, ...] = (
    "tallest-tower-share", "towers-per-block", "largest-group-share", "longest-row-share",
    "longest-column-share", "bowls-occupied-share", "fullest-bowl-share", "regions-used-per-block",
)
FEATURE_NAMES: tuple[str, ...] = tuple(f"{c}:{r}" for c in CLASSES for r in RELATIONS) + tuple(
    f"global:{g}" for g in GLOBALS)
N_FEATURES = len(FEATURE_NAMES)


@memoized(size=64, why="a colour: a pure function of it (the mask is shared: callers must not change it)")
def _class_mask(color: str) -> np.ndarray:
    """Which classes a block of ``color`` belongs to."""
    m = np.zeros(len(CLASSES), bool)
    m[0] = True
    m[1] = color in WARM_COLORS
    m[2] = color in COOL_COLORS
    m[3 + COLOR_NAMES.index(color)] = True
    return m


def _components(adj: dict[str, set[str]]) -> list[list[str]]:
    """Connected components of a symmetric adjacency (every node a key)."""
    seen: set[str] = set()
    out = []
    for n in adj:
        if n in seen:
            continue
        comp, todo = [], [n]
        seen.add(n)
        while todo:
            a = todo.pop()
            comp.append(a)
            for b in adj[a]:
                if b not in seen:
                    seen.add(b)
                    todo.append(b)
        out.append(comp)
    return out


class _Graphs:
    """The block graphs φ reads, built once per state: neighbours (``Facts.near``), blocks
    touching (neighbours or stacked), and flat neighbours aligned in a row / a column."""

    def __init__(self, f: Facts):
        blocks = set(f.blocks)
        self.near: dict[str, set[str]] = {n: set() for n in (*f.blocks, *f.bowls)}
        for pair in f.near:
            if len(pair) == 2:
                a, b = tuple(pair)
                self.near.setdefault(a, set()).add(b)
                self.near.setdefault(b, set()).add(a)
        self.touching = {b: self.near[b] & blocks for b in f.blocks}
        for b in f.blocks:
            under = f.below.get(b)
            if under is not None and under in blocks and under != b:
                self.touching[b].add(under)
                self.touching[under].add(b)
        flat = {b for b in f.blocks if f.flat(b)}
        self.row = {b: set() for b in f.blocks}
        self.column = {b: set() for b in f.blocks}
        for a in flat:
            for b in self.near[a] & flat:
                if a != b:
                    if abs(f.xy[a][1] - f.xy[b][1]) <= ALIGN_TOL:
                        self.row[a].add(b)
                    if abs(f.xy[a][0] - f.xy[b][0]) <= ALIGN_TOL:
                        self.column[a].add(b)


def block_relations(f: Facts, g: _Graphs | None = None) -> dict[str, list[bool]]:
    """Per block, the 0/1 list of RELATIONS."""
    g = g or _Graphs(f)
    blocks = set(f.blocks)
    bowls = set(f.bowls)
    group = {b for comp in _components(g.touching) if len(comp) > 1 for b in comp}
    out = {}
    for b in f.blocks:
        own = f"{color_of(b)} bowl"
        bowl = f.bowl_of.get(b)
        near_bowls = g.near[b] & bowls
        cell = f.cell.get(b)
        out[b] = [
            bowl is not None,
            bowl == own,
            bowl is not None and bowl != own,
            f.below.get(b) is not None,
            f.above.get(b) is not None,
            f.flat(b),
            bool(g.near[b] & blocks - {b}),
            bool(near_bowls),
            own in near_bowls,
            bool(near_bowls - {own}),
            *(cell == r for r in REGIONS),
            bool(g.row[b]),
            bool(g.column[b]),
            f.below.get(b) is not None or f.above.get(b) is not None,
            b in group,
        ]
    return out


def _globals(f: Facts, g: _Graphs) -> np.ndarray:
    blocks = list(f.blocks)
    n = max(len(blocks), 1)
    bases = [b for b in blocks if f.below.get(b) is None]
    heights = [len(f.tower(b)) for b in bases] or [0]
    towers = sum(h >= 2 for h in heights)
    groups = _components(g.touching)
    rows = _components(g.row)
    cols = _components(g.column)
    per_bowl = [sum(f.bowl_of.get(b) == w for b in blocks) for w in f.bowls]
    regions = {f.cell.get(b) for b in blocks}
    return np.array([
        max(heights) / n if max(heights) >= 2 else 0.0,
        towers / n,
        max((len(c) for c in groups if len(c) > 1), default=0) / n,
        max((len(c) for c in rows if len(c) > 1), default=0) / n,
        max((len(c) for c in cols if len(c) > 1), default=0) / n,
        sum(c > 0 for c in per_bowl) / max(len(per_bowl), 1),
        max(per_bowl, default=0) / n,
        len(regions) / n if blocks else 0.0,
    ], float)


def phi_facts(f: Facts) -> np.ndarray:
    """φ of the state behind ``f`` (memoised on it)."""
    got = f.memo.get("reward-phi")
    if got is not None:
        return got
    g = _Graphs(f)
    rel = block_relations(f, g)
    if rel:
        masks = np.array([_class_mask(color_of(b)) for b in rel], float)  # [blocks, classes]
        sums = masks.T @ np.array(list(rel.values()), float)  # exact: sums of 0/1
        counts = masks.sum(axis=0)
    else:
        sums, counts = np.zeros((len(CLASSES), len(RELATIONS))), np.zeros(len(CLASSES))
    frac = np.divide(sums, counts[:, None], out=np.zeros_like(sums), where=counts[:, None] > 0)
    got = np.concatenate([frac.reshape(-1), _globals(f, g)])
    got.setflags(write=False)
    f.memo["reward-phi"] = got
    return got


def phi(state: WorldState) -> np.ndarray:
    """φ(s) ∈ [0, 1]^N_FEATURES."""
    return phi_facts(facts(state))


def present(objects) -> np.ndarray:
    """Which features can be non-zero in a scene of ``objects`` (classes with a block there)."""
    colors = [color_of(o) for o in objects if kind_of(o) == "block"]
    has = np.zeros(len(CLASSES), bool)
    for c in colors:
        has |= _class_mask(c)
    return np.concatenate([np.repeat(has, len(RELATIONS)), np.ones(len(GLOBALS), bool)])
