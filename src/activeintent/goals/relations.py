"""The relations of the goal language: a property of one block in a state (in a bowl, on a
block, on the table, next to, on a side of, in a region of the table), with the regions and
the unregistered relations the bayes grammar uses (InCell, Flat)."""

from __future__ import annotations

from activeintent.goals.facts import Facts, facts
from activeintent.goals.nodes import Relation, register
from activeintent.goals.planning import GRID, area_points, free_points, nearest_points
from activeintent.memo import memoized
from activeintent.world import BLOCK_SIZE, PutIn, PutNextTo, PutOn
from activeintent.world.colors import COLOR_NAMES, WARM_COLORS
from activeintent.world.relations import table_position_name
from activeintent.world.scene import ALL_OBJECTS, color_of, footprint_radius, kind_of, own_bowl
from activeintent.world.skills import SIDES


def _class(block_or_bowl: str) -> str:
    return "warm" if color_of(block_or_bowl) in WARM_COLORS else "cool"


def _kin(a: str, b: str, p: str) -> bool:
    """Does object ``b`` stand in colour relation ``p`` to block ``a``: same / other colour,
    same-class / other-class (warm vs cool), or of class warm / cool."""
    if p == "any":
        return True
    if p == "same":
        return color_of(a) == color_of(b)
    if p == "other":
        return color_of(a) != color_of(b)
    if p == "same-class":
        return _class(a) == _class(b)
    if p == "other-class":
        return _class(a) != _class(b)
    return _class(b) == p  # "warm" | "cool"


KIN_WORDS = {"any": "", "same": "of its own colour", "other": "of another colour",
             "same-class": "of its own colour class (warm / cool)", "other-class": "of the other colour class (warm / cool)",
             "warm": "of a warm colour", "cool": "of a cool colour"}


class InBowl(Relation):
    key = "in-bowl"
    params = ("any", "same", "other", "same-class", "other-class", "warm", "cool")

    def phrase(self, p):
        return {"any": "in a bowl", "same": "in the bowl of its own colour"}.get(p, f"in a bowl {KIN_WORDS[p]}")

    def _fits(self, b, w, p):
        return _kin(b, w, p)

    def ok(self, f, b, p):
        w = f.bowl_of[b]
        return w is not None and self._fits(b, w, p)

    def possible(self, b, objects, p):
        return any(kind_of(o) == "bowl" and self._fits(b, o, p) for o in objects)

    def targets(self, state, b, p):
        return [PutIn(block=b, bowl=w) for w in state.bowls if self._fits(b, w, p)]


class InNamedBowl(Relation):
    key = "in-the-bowl"
    params = COLOR_NAMES

    def phrase(self, p):
        return f"in the {p} bowl"

    def refers(self, p):
        return f"{p} bowl"

    def ok(self, f, b, p):
        return f.bowl_of[b] == f"{p} bowl"

    def targets(self, state, b, p):
        return [PutIn(block=b, bowl=f"{p} bowl")]


class OnBlock(Relation):
    key = "on-block"
    params = ("any", "same-class", "other-class", "warm", "cool")

    def phrase(self, p):
        return "on top of another block" + (f" {KIN_WORDS[p]}" if p != "any" else "")

    def ok(self, f, b, p):
        under = f.below[b]
        return under is not None and _kin(b, under, p)

    def possible(self, b, objects, p):
        return any(kind_of(o) == "block" and o != b and _kin(b, o, p) for o in objects)

    def targets(self, state, b, p):
        f = facts(state)
        return [PutOn(block=b, target=o) for o in state.blocks if o != b and f.clear(o) and _kin(b, o, p)]


class OnNamedBlock(Relation):
    key = "on-the-block"
    params = COLOR_NAMES

    def phrase(self, p):
        return f"on the {p} block"

    def refers(self, p):
        return f"{p} block"

    def ok(self, f, b, p):
        return f.below[b] == f"{p} block"

    def targets(self, state, b, p):
        return [PutOn(block=b, target=f"{p} block")]


class OnTable(Relation):
    key = "on-table"

    def phrase(self, p):
        return "flat on the table (not in a bowl, not on a block)"

    def ok(self, f, b, p):
        return b in f.on_table and f.below[b] is None

    def targets(self, state, b, p):
        return free_points(state, nearest_points(state, b), b, 8)


# "next to any ...": the kind of object and, for blocks, its colour relation to the block placed
NEAR_ANY = {"a-bowl": ("bowl", "any"), "a-block": ("block", "any"),
            "block-same-class": ("block", "same-class"), "block-other-class": ("block", "other-class")}


class NextTo(Relation):
    """Next to a named object, to the bowl of its own colour, or to any bowl / block (of a kin)."""

    key = "next-to"
    params = ALL_OBJECTS + ("own-bowl",) + tuple(NEAR_ANY)

    def phrase(self, p):
        if p == "own-bowl":
            return "next to the bowl of its own colour"
        if p in NEAR_ANY:
            kind, kin = NEAR_ANY[p]
            return "next to a bowl" if kind == "bowl" else " ".join(
                w for w in ("next to another block", KIN_WORDS[kin]) if w)
        return f"next to the {p}"

    def refers(self, p):
        return None if p == "own-bowl" or p in NEAR_ANY else p

    def _targets(self, b, objects, p) -> list[str]:
        if p == "own-bowl":
            return [own_bowl(b)] if own_bowl(b) in objects else []
        if p in NEAR_ANY:
            kind, kin = NEAR_ANY[p]
            return [o for o in objects if kind_of(o) == kind and o != b and _kin(b, o, kin)]
        return [p] if p in objects and p != b else []

    def ok(self, f, b, p):
        if p not in NEAR_ANY:
            t = own_bowl(b) if p == "own-bowl" else p
            return f.next_to(b, t)
        return any(f.next_to(b, t) for t in self._targets(b, tuple(f.blocks) + tuple(f.bowls), p))

    def possible(self, b, objects, p):
        return bool(self._targets(b, tuple(objects), p))

    def targets(self, state, b, p):
        return [PutNextTo(block=b, target=t, side=s) for t in self._targets(b, tuple(state.names), p)
                for s in ("nearest", *SIDES)]


SIDE_WORDS = {"left": "left of", "right": "right of", "front": "in front of", "behind": "behind"}


class Beside(Relation):
    """Entirely on one side of an object (left/right along x, front/behind along y), not in a bowl."""

    key = "side"
    params = tuple(f"{s}/{o}" for s in SIDES for o in ALL_OBJECTS + ("own-bowl",))

    def phrase(self, p):
        s, o = p.split("/")
        return f"{SIDE_WORDS[s]} the bowl of its own colour" if o == "own-bowl" else f"{SIDE_WORDS[s]} the {o}"

    def refers(self, p):
        o = p.split("/")[1]
        return None if o == "own-bowl" else o

    def possible(self, b, objects, p):
        o = p.split("/")[1]
        o = own_bowl(b) if o == "own-bowl" else o
        return o in objects and o != b

    @staticmethod
    def beyond(xy_b, xy_o, o: str, s: str) -> bool:
        reach = footprint_radius(o) + BLOCK_SIZE / 2 - 0.004
        dx, dy = xy_b[0] - xy_o[0], xy_b[1] - xy_o[1]
        return {"left": -dx, "right": dx, "front": -dy, "behind": dy}[s] >= reach

    def ok(self, f, b, p):
        s, o = p.split("/")
        o = own_bowl(b) if o == "own-bowl" else o
        return o in f.xy and f.bowl_of[b] is None and self.beyond(f.xy[b], f.xy[o], o, s)

    def targets(self, state, b, p):
        s, o = p.split("/")
        o = own_bowl(b) if o == "own-bowl" else o
        if o not in state.positions:
            return []
        xy_o = state.pos(o)[:2]
        pts = [q for q in GRID if self.beyond(q, xy_o, o, s)]
        return [PutNextTo(block=b, target=o, side=s)] + free_points(state, nearest_points(state, o, pts), b, 5)


CORNER_CELL = {"back left corner": "top left corner", "back right corner": "top right corner",
               "front left corner": "bottom left corner", "front right corner": "bottom right corner"}


def _cell(name: str):
    return lambda xy: table_position_name(xy) == name


REGIONS = {
    "left half": lambda xy: xy[0] < 0.0,
    "right half": lambda xy: xy[0] > 0.0,
    "back half": lambda xy: xy[1] > -0.5,
    "front half": lambda xy: xy[1] < -0.5,
    "back strip": lambda xy: xy[1] > -0.4,
    "front strip": lambda xy: xy[1] < -0.6,
    "centre": lambda xy: abs(xy[0]) < 0.1 and abs(xy[1] + 0.5) < 0.1,
    **{corner: _cell(cell) for corner, cell in CORNER_CELL.items()},
}


def in_region(f: Facts, b: str, region: str) -> bool:
    """REGIONS[region](f.xy[b]), reading a corner from the state's own cell names (the same
    grid: the hot path asks this for every block, corner and state)."""
    cell = CORNER_CELL.get(region)
    return f.cell[b] == cell if cell is not None else REGIONS[region](f.xy[b])


def region_points(region: str) -> list[tuple[float, float]]:
    """The grid points inside ``region``, nearest its centre first."""
    return list(_region_points(region))


def _area_points(inside) -> tuple[tuple[float, float], ...]:
    """The grid points ``inside`` holds, nearest their centre first."""
    return tuple(area_points(inside))


@memoized(size=64, why="a region's name (REGIONS, a constant): planners ask on every step; the grid never changes")
def _region_points(region: str) -> tuple[tuple[float, float], ...]:
    return _area_points(REGIONS[region])


class InRegion(Relation):
    key = "region"
    params = tuple(REGIONS)

    def phrase(self, p):
        return f"in the {p} of the table (front = near the person, back = far side; not in a bowl)"

    def ok(self, f, b, p):
        return b in f.on_table and f.below[b] is None and in_region(f, b, p)

    def area(self, p: str):
        """The region's test on a table point (x, y)."""
        return REGIONS[p]

    def targets(self, state, b, p):
        return free_points(state, region_points(p), b, 10)


# The cells of the table's 3 × 3 grid (world.relations' names) that no region above names.
CELLS = {name: _cell(name) for name in ("top side", "left side", "middle", "right side", "bottom side")}


class InCell(Relation):
    """In one of the table's side cells or its middle cell, not in a bowl. Not registered: not in
    the lang learners' language (registering it would change every goal's prior); the bayes
    grammar's regions use it. Its "middle" is the grid cell, closed on two sides, where the
    region "centre" is open."""

    key = "cell"
    params = tuple(CELLS)

    def phrase(self, p):
        return f"in the {p} cell of the table (not in a bowl)"

    def ok(self, f, b, p):
        return b in f.on_table and f.below[b] is None and f.cell[b] == p

    def area(self, p: str):
        return CELLS[p]

    def targets(self, state, b, p):
        return free_points(state, _area_points(CELLS[p]), b, 10)


class Flat(Relation):
    """``inner`` and flat on the table (not in a bowl, not on a block, nothing on it). Not
    registered (see InCell): "flat on the table" and "next to …, flat on the table" of the
    bayes grammar, where OnTable and NextTo allow a block with another one on top."""

    def __init__(self, inner: Relation):
        self.inner = inner
        self.key = f"flat-{inner.key}"
        self.params = inner.params

    def phrase(self, p):
        return f"{self.inner.phrase(p)}, flat on the table with nothing on it"

    def ok(self, f, b, p):
        return self.inner.ok(f, b, p) and f.flat(b)

    def refers(self, p):
        return self.inner.refers(p)

    def possible(self, b, objects, p):
        return self.inner.possible(b, objects, p)

    def targets(self, state, b, p):
        return self.inner.targets(state, b, p)


for _node in (InBowl(), InNamedBowl(), OnBlock(), OnNamedBlock(), OnTable(), NextTo(), Beside(), InRegion()):
    register(_node)
