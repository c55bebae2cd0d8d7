"""Facts: the symbolic relations of one world state in the form hypotheses read quickly.

The record of a state's relations is world.relations' (geometry to relations, in one place);
Facts index that record (per block: its bowl, below, above; neighbours as a set) with the
positions and a per-state memo, built once per state (and cached), so that hundreds of
hypotheses can judge the same predicted state without recomputing anything.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from activeintent.memo import BoundedCache
from activeintent.world import WorldState, relations
from activeintent.world.colors import COOL_COLORS, WARM_COLORS
from activeintent.world.scene import color_of

ALIGN_TOL = 0.02  # half a block: centres this close in y (x) count as one row (column)


@dataclass(eq=False)
class Facts:
    """Relations of a state: per block its bowl, what it stands on, what is on it, neighbours."""

    blocks: tuple[str, ...]
    bowls: tuple[str, ...]
    bowl_of: dict[str, str | None]
    below: dict[str, str | None]
    above: dict[str, str | None]
    on_table: frozenset[str]
    near: frozenset[frozenset[str]]
    xy: dict[str, tuple[float, float]]
    cell: dict[str, str]
    pos: dict[str, tuple[float, float, float]]
    memo: dict = field(default_factory=dict)  # per-state cache (groups of clauses)

    def next_to(self, a: str, b: str) -> bool:
        return frozenset((a, b)) in self.near

    def base(self, block: str) -> str:
        """The bottom block of the tower ``block`` belongs to."""
        seen = {block}
        while (under := self.below.get(block)) is not None and under not in seen:
            seen.add(under)
            block = under
        return block

    def tower(self, base: str) -> list[str]:
        """Blocks of the tower standing on ``base``, bottom to top."""
        chain = [base]
        while (top := self.above.get(chain[-1])) is not None and top not in chain:
            chain.append(top)
        return chain

    def flat(self, block: str) -> bool:
        """Resting directly on the table: not in a bowl, not on a block, nothing on it."""
        return block in self.on_table and self.below[block] is None and self.above[block] is None

    def clear(self, block: str) -> bool:
        return self.above.get(block) is None


def is_warm(block: str) -> bool:
    return color_of(block) in WARM_COLORS


def is_cool(block: str) -> bool:
    return color_of(block) in COOL_COLORS


def _key(state: WorldState) -> tuple:
    # Exact positions: a key rounded to 0.1 mm handed a state the Facts (xy, pos) of an earlier,
    # slightly different one, so an episode depended on what the process had computed before.
    return tuple((n, float(p[0]), float(p[1]), float(p[2])) for n, p in state.positions.items())


def state_key(f: Facts) -> tuple:
    """Identity of the state behind ``f`` (positions to 1 mm; kept on ``f``)."""
    got = f.memo.get("state_key")
    if got is None:
        got = f.memo["state_key"] = tuple((n, round(p[0], 3), round(p[1], 3), round(p[2], 3))
                                          for n, p in f.pos.items())
    return got


# by exact positions; Facts are a pure function of them
_CACHE: BoundedCache[tuple, Facts] = BoundedCache(20000)


def facts(state: WorldState) -> Facts:
    """Facts of ``state`` (memoised on its exact positions)."""
    key = _key(state)
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    rel = relations(state)
    blocks = tuple(state.blocks)
    below = {b: rel.below(b) for b in blocks}
    above = {b: rel.above(b) for b in blocks}
    f = Facts(
        blocks=blocks,
        bowls=tuple(state.bowls),
        bowl_of={b: rel.in_bowl(b) for b in blocks},
        below=below,
        above=above,
        on_table=frozenset(rel.on_table),
        near=frozenset(frozenset(p) for p in rel.next_to),
        xy={n: (float(p[0]), float(p[1])) for n, p in state.positions.items()},
        cell=dict(rel.table_position),
        pos=dict(state.positions),
    )
    return _CACHE.put(key, f)
