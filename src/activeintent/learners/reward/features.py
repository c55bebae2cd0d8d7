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

import functools

import numpy as np

from activeintent.goals.facts import ALIGN_TOL, Facts, facts
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


@functools.cache
def _class_mask(color: str) -> np.ndarray:
    """Which classes a block of ``color`` belongs to."""
    m = np.zeros(len(CLASSES), bool)
    m[0] = True
    m[1] = color in WARM_COLORS
    m[2] = color in COOL_COLORS
    m[3 + COLOR_NAMES.index(color)] = True
    return m


def _components(nodes: list[str], linked) -> list[list[str]]:
    seen: set[str] = set()
    out = []
    for n in nodes:
        if n in seen:
            continue
        comp, todo = [], [n]
        seen.add(n)
        while todo:
            a = todo.pop()
            comp.append(a)
            for b in nodes:
                if b not in seen and linked(a, b):
                    seen.add(b)
                    todo.append(b)
        out.append(comp)
    return out


def _line(f: Facts, a: str, b: str, axis: int) -> bool:
    """a and b flat, side by side and aligned across ``axis`` (1: a left-right row, 0: a column)."""
    return (f.flat(a) and f.flat(b) and f.next_to(a, b)
            and abs(f.xy[a][axis] - f.xy[b][axis]) <= ALIGN_TOL)


def block_relations(f: Facts) -> dict[str, np.ndarray]:
    """Per block, the 0/1 vector of RELATIONS."""
    blocks = list(f.blocks)
    bowls = list(f.bowls)
    stacked = lambda a, b: f.below.get(a) == b or f.below.get(b) == a  # noqa: E731
    touching = lambda a, b: f.next_to(a, b) or stacked(a, b)  # noqa: E731
    group = {b for comp in _components(blocks, touching) if len(comp) > 1 for b in comp}
    out = {}
    for b in blocks:
        own = f"{color_of(b)} bowl"
        bowl = f.bowl_of.get(b)
        near_bowls = [w for w in bowls if f.next_to(b, w)]
        v = [
            bowl is not None,
            bowl == own,
            bowl is not None and bowl != own,
            f.below.get(b) is not None,
            f.above.get(b) is not None,
            f.flat(b),
            any(f.next_to(b, o) for o in blocks if o != b),
            bool(near_bowls),
            own in near_bowls,
            any(w != own for w in near_bowls),
            *(f.cell.get(b) == r for r in REGIONS),
            any(_line(f, b, o, 1) for o in blocks if o != b),
            any(_line(f, b, o, 0) for o in blocks if o != b),
            f.below.get(b) is not None or f.above.get(b) is not None,
            b in group,
        ]
        out[b] = np.array(v, float)
    return out


def _globals(f: Facts) -> np.ndarray:
    blocks = list(f.blocks)
    n = max(len(blocks), 1)
    bases = [b for b in blocks if f.below.get(b) is None]
    heights = [len(f.tower(b)) for b in bases] or [0]
    towers = sum(h >= 2 for h in heights)
    stacked = lambda a, b: f.below.get(a) == b or f.below.get(b) == a  # noqa: E731
    groups = _components(blocks, lambda a, b: f.next_to(a, b) or stacked(a, b))
    rows = _components(blocks, lambda a, b: _line(f, a, b, 1))
    cols = _components(blocks, lambda a, b: _line(f, a, b, 0))
    per_bowl = [sum(f.bowl_of.get(b) == w for b in blocks) for w in f.bowls]
    regions = {f.cell.get(b) for b in blocks}
    return np.array([
        max(heights) / n if max(heights) >= 2 else 0.0,
        towers / n,
        max((len(g) for g in groups if len(g) > 1), default=0) / n,
        max((len(g) for g in rows if len(g) > 1), default=0) / n,
        max((len(g) for g in cols if len(g) > 1), default=0) / n,
        sum(c > 0 for c in per_bowl) / max(len(per_bowl), 1),
        max(per_bowl, default=0) / n,
        len(regions) / n if blocks else 0.0,
    ], float)


def phi_facts(f: Facts) -> np.ndarray:
    """φ of the state behind ``f`` (memoised on it)."""
    got = f.memo.get("reward-phi")
    if got is not None:
        return got
    rel = block_relations(f)
    sums = np.zeros((len(CLASSES), len(RELATIONS)))
    counts = np.zeros(len(CLASSES))
    for b, v in rel.items():
        m = _class_mask(color_of(b))
        sums[m] += v
        counts[m] += 1
    frac = np.divide(sums, counts[:, None], out=np.zeros_like(sums), where=counts[:, None] > 0)
    got = np.concatenate([frac.reshape(-1), _globals(f)])
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
