"""The structures of the goal language: a shape a whole group takes (a line, towers, blocks in
bowls, clusters, corners, groups by colour class) and where it stands (Placed), with the
colour orders they are built in and the unregistered structures the library, the dev suite and
the bayes grammar use."""

from __future__ import annotations

import math
from itertools import combinations

from activeintent.goals.facts import ALIGN_TOL, Facts, facts
from activeintent.goals.nodes import Group, Structure, register
from activeintent.goals.planning import free_points, nearest_points
from activeintent.goals.relations import (
    CORNER_CELL,
    OnTable,
    _area_points,
    _class,
    in_region,
    region_points,
)
from activeintent.memo import memoized
from activeintent.world import BOUNDS, PutIn, PutNextTo, PutOn, Skill
from activeintent.world.colors import COLOR_NAMES, WARM_COLORS
from activeintent.world.scene import MIN_SPACING, color_of, kind_of

# The order "in rainbow order" sorts by: the rainbow from red to purple, then pink, brown, gray.
TEN_COLOUR_ORDER = ("red", "orange", "yellow", "green", "cyan", "blue", "purple", "pink", "brown", "gray")
# The rainbow proper: red to purple (the dev suite's rainbow row; RED_TO_PURPLE).
SEVEN_RAINBOW_COLOURS = TEN_COLOUR_ORDER[:7]
NUMBER = {"1": "one", "2": "two"}  # counts in words


def _rank(b: str) -> int:
    return TEN_COLOUR_ORDER.index(color_of(b))


def _flat(f: Facts, b: str) -> bool:
    return b in f.on_table and f.below[b] is None and f.above[b] is None


def _rests_on_table(f: Facts, b: str) -> bool:
    """Directly on the table (not in a bowl, not on a block); another block may stand on it."""
    return b in f.on_table and f.below[b] is None


ORDERS = ("any", "rainbow", "warm-first", "cool-first")
ORDER_WORDS = {"rainbow": "in rainbow order", "warm-first": "the warm-coloured ones first",
               "cool-first": "the cool-coloured ones first"}


# An order outside ORDERS (not in the language): the rainbow from red to purple, where a block of
# pink, brown or gray has no place (the dev suite's rainbow row).
RED_TO_PURPLE = "red-to-purple"


ORDER_KEYS: dict = {}  # orders of later node types (requested.py), by name: their sort keys


def _order_key(order: str):
    """Sort key of an order: the rainbow rank, or the colour class (then the rainbow rank, so
    that a plan has one target; any arrangement with the classes in order satisfies it)."""
    if order in ORDER_KEYS:
        return ORDER_KEYS[order]
    if order in ("rainbow", RED_TO_PURPLE):
        return _rank
    first = "warm" if order == "warm-first" else "cool"
    return lambda b: (_class(b) != first, _rank(b))


def in_order(seq, order: str) -> bool:
    """Is ``seq`` (left→right, front→back or bottom→top) in ``order``?"""
    if order == "any":
        return True
    if order == "rainbow":
        return list(seq) == sorted(seq, key=_rank)
    if order == RED_TO_PURPLE:
        return all(color_of(b) in SEVEN_RAINBOW_COLOURS for b in seq) and list(seq) == sorted(seq, key=_rank)
    first = "warm" if order == "warm-first" else "cool"
    ks = [_class(b) != first for b in seq]
    return ks == sorted(ks)


class Line(Structure):
    """A straight row (axis 1: same y, along x) or column (axis 0: same x, along y) of flat
    blocks, neighbours next to each other; in an order left→right / front→back (ORDERS)."""

    params = ORDERS
    axis = 1
    sides = ("right", "left")
    words = ("one left-to-right row", "left to right")

    def __init__(self, min_size: int | None = None, beside_any: bool = False, loaded: bool = False,
                 order_beside: bool = False):
        """``beside_any``: a moved block set beside any block, not only one of the group, must be
        in line with one of them (the bayes grammar's row and column). ``loaded``: a block of
        the line only has to rest on the table, another block may stand on it (the library's
        align and align-vertical; by default the blocks of a line are flat, nothing on them).
        ``order_beside``: a moved block may be set beside blocks out of line, but with every
        block it is in line beside it must make a line in the order (the dev suite's rainbow
        row; by default it must be in line with one of its neighbours, whatever the order)."""
        super().__init__(min_size)
        self.beside_any = beside_any
        self.loaded = loaded
        self.order_beside = order_beside

    def member(self, f: Facts, b: str) -> bool:
        """Can ``b`` be part of a line where it stands?"""
        return _rests_on_table(f, b) if self.loaded else _flat(f, b)

    def sentence(self, subject, p):
        text = f"{subject} form {self.words[0]} on the table, each next to its neighbour"
        return text + (f", {ORDER_WORDS[p]} {self.words[1]}" if p != "any" else "")

    def line(self, f: Facts, blocks, p: str) -> bool:
        if len(blocks) < 1 or not all(self.member(f, b) for b in blocks):
            return False
        across = [f.xy[b][self.axis] for b in blocks]
        if max(across) - min(across) > ALIGN_TOL:
            return False
        along = sorted(blocks, key=lambda b: f.xy[b][1 - self.axis])
        if not in_order(along, p):
            return False
        return all(f.xy[b][1 - self.axis] - f.xy[a][1 - self.axis] >= MIN_SPACING and f.next_to(a, b)
                   for a, b in zip(along, along[1:], strict=False))

    def holds(self, f, g, p):
        return self.line(f, g, p)

    def best(self, f: Facts, g: Group, p: str) -> tuple[str, ...]:
        flat = [b for b in g if self.member(f, b)]
        for size in range(len(flat), 1, -1):
            for c in combinations(flat, size):
                if self.line(f, c, p):
                    return c
        return tuple(flat[:1])

    def score(self, f, g, p):
        return len(self.best(f, g, p)) / len(g) if g else 1.0

    def moved_ok(self, fb, fa, g, b, p):
        if not self.member(fa, b):
            return False
        v = fa.xy[b][self.axis]
        near = [o for o in (fa.blocks if self.beside_any else g) if o != b and self.member(fa, o) and fa.next_to(b, o)]
        if self.order_beside:
            return all(self.line(fa, (b, o), p) for o in near if abs(fa.xy[o][self.axis] - v) <= ALIGN_TOL)
        return not near or any(abs(fa.xy[o][self.axis] - v) <= ALIGN_TOL for o in near)

    def suggest(self, state, g, p):
        f = facts(state)
        chain = sorted(self.best(f, g, p), key=lambda b: f.xy[b][1 - self.axis])
        rest = [b for b in g if b not in chain]
        if not chain:
            return []
        lo, hi = chain[0], chain[-1]
        out: list[Skill] = []
        if p != "any":  # build the order from its first block on: the prefix in line, then the next
            want = sorted(g, key=_order_key(p))
            k = max((n for n in range(1, len(want) + 1) if self.line(f, tuple(want[:n]), p)), default=0)
            if k == 0:
                out += free_points(state, nearest_points(state, want[0]), want[0], 4)
            elif k < len(want):
                out.append(PutNextTo(block=want[k], target=want[k - 1], side=self.sides[0]))
        for b in sorted(rest, key=_order_key(p)) if p != "any" else rest:
            out += [PutNextTo(block=b, target=hi, side=self.sides[0]), PutNextTo(block=b, target=lo, side=self.sides[1])]
        return out


class Row(Line):
    key = "row"


class Column(Line):
    key = "column"
    axis = 0
    sides = ("behind", "front")
    words = ("one front-to-back column", "front to back")


# The left edge with its border in: centres at most EDGE from the table's left edge (Placed's
# "left-edge" leaves the border out).
def along_left_edge(xy) -> bool:
    return float(xy[0]) <= BOUNDS[0][0] + EDGE + 1e-9


class LineWithin(Structure):
    """A line (``line``: a Row or Column) of blocks all inside an ``area`` of the table, scored by
    the longest such line inside the area; a moved block must rest in the area (the line's rule
    on neighbours is not asked). Not registered (see InCell): Placed(Column) at the left edge
    scores the mean of the shape and the share in place. The dev suite's column along the left
    edge."""

    def __init__(self, line: Line, area, area_key: str, area_words: str):
        self.line = line
        self.area = area
        self.key = f"{line.key}-within-{area_key}"
        self.params = line.params
        self.area_words = area_words

    def sentence(self, subject, p):
        return f"{self.line.sentence(subject, p)}, {self.area_words}"

    def inside(self, f: Facts, g: Group) -> Group:
        return tuple(b for b in g if self.area(f.xy[b]))

    def holds(self, f, g, p):
        return len(self.inside(f, g)) == len(g) and self.line.line(f, g, p)

    def score(self, f, g, p):
        return len(self.line.best(f, self.inside(f, g), p)) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        return self.line.member(fa, b) and bool(self.area(fa.xy[b]))

    def suggest(self, state, g, p):
        return self.line.suggest(state, g, p)


def _towers(f: Facts, g: Group, on_table: bool = True) -> list[list[str]]:
    """Towers made only of group blocks, standing on the table (a pile in a bowl is no tower; a
    lone block on the table is a tower of height 1), bottom to top, tallest first; with
    ``on_table`` False also those standing in a bowl."""
    gs = set(g)
    out = []
    for b in g:
        if f.below[b] is None and (b in f.on_table or not on_table):
            chain = f.tower(b)
            if all(c in gs for c in chain):
                out.append(chain)
    return sorted(out, key=len, reverse=True)


def _ordered_height(f: Facts, g: Group, order: str = "rainbow") -> int:
    """How many blocks of the ordered group already stand in order from the bottom."""
    want = sorted(g, key=_order_key(order))
    if f.below[want[0]] is not None:
        return 0
    chain = f.tower(want[0])
    n = 0
    while n < len(chain) and n < len(want) and chain[n] == want[n]:
        n += 1
    return n


class Tower(Structure):
    key = "tower"
    params = ORDERS

    def __init__(self, min_size: int | None = None, lone_flat: bool = False, onto_standing: bool = False):
        """``lone_flat``: a group of one block is a tower of height 1, so that block must stay flat
        on the table when moved (the bayes grammar's tower, shown by lone blocks too).
        ``onto_standing``: a moved block must end on a block of a tower standing on the table (a
        pile in a bowl is no tower, a lone block is not stacked): the library's stack."""
        super().__init__(min_size)
        self.lone_flat = lone_flat
        self.onto_standing = onto_standing

    def sentence(self, subject, p):
        return f"{subject} are stacked into one tower" + (f", {ORDER_WORDS[p]} from the bottom up" if p != "any" else "")

    def holds(self, f, g, p):
        if p == "rainbow":
            return _ordered_height(f, g) == len(g) and f.above[sorted(g, key=_rank)[-1]] is None
        t = _towers(f, g)
        return bool(t) and len(t[0]) == len(g) and in_order(t[0], p)

    def score(self, f, g, p):
        if p == "any":
            t = _towers(f, g)
            return len(t[0]) / len(g) if t else 0.0
        return 1.0 if self.holds(f, g, p) else _ordered_height(f, g, p) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        if self.onto_standing:
            return fa.below[b] is not None and any(b in t for t in _towers(fa, g))
        return fa.below[b] is not None or (len(g) == 1 and (not self.lone_flat or fa.flat(b)))

    def bases(self, f: Facts, g: Group, p: str) -> list[str]:
        """Where the tower can grow from, in any order (``p`` "any"): the bottoms of the group's
        towers, tallest first."""
        return [t[0] for t in _towers(f, g)]

    def suggest(self, state, g, p):
        f = facts(state)
        if p != "any":
            want = sorted(g, key=_order_key(p))
            n = _ordered_height(f, g, p)
            if n == 0:
                return free_points(state, nearest_points(state, want[0]), want[0], 6)
            return [PutOn(block=want[n], target=want[n - 1])] if n < len(want) else []
        t = _towers(f, g)
        out: list[Skill] = []
        for tower in t[:2]:
            out += [PutOn(block=b, target=tower[-1]) for b in g if b not in tower]
        return out


class TowerByBowl(Tower):
    """One tower of the group standing on the table with its bottom block right next to a bowl
    (any bowl); scored by the tallest such tower; a moved block must end in one (a lone block
    by a bowl is a tower of one). Not registered (see InCell): Placed(Tower) "by-a-bowl" scores
    the mean of the shape and the share in place. The dev suite's tower beside a bowl."""

    key = "tower-by-bowl"
    params = ("any",)

    def sentence(self, subject, p):
        return f"{subject} are stacked into one tower standing on the table right next to a bowl"

    def by_bowl(self, f: Facts, g: Group) -> list[list[str]]:
        return [t for t in _towers(f, g) if any(f.next_to(t[0], w) for w in f.bowls)]

    def holds(self, f, g, p):
        return any(len(t) == len(g) for t in self.by_bowl(f, g))

    def score(self, f, g, p):
        return max((len(t) for t in self.by_bowl(f, g)), default=0) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        return any(b in t for t in self.by_bowl(fa, g))

    def possible(self, g, objects, p):
        return len(g) >= self.min_size and any(kind_of(o) == "bowl" for o in objects)


class TowersByClass(Structure):
    key = "towers-by-class"
    min_size = 2

    def sentence(self, subject, p):
        return f"{subject} form two towers: one of the warm-coloured blocks and one of the cool-coloured ones"

    @staticmethod
    def parts(g):
        warm = tuple(b for b in g if color_of(b) in WARM_COLORS)
        return [x for x in (warm, tuple(b for b in g if b not in warm)) if x]

    def holds(self, f, g, p):
        return all(Tower().holds(f, part, "any") for part in self.parts(g))

    def score(self, f, g, p):
        return sum(Tower().score(f, part, "any") * len(part) for part in self.parts(g)) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        part = next(x for x in self.parts(g) if b in x)
        return len(part) == 1 or (fa.below[b] is not None and fa.below[b] in part)

    def possible(self, g, objects, p):
        return len(self.parts(g)) == 2 and len(g) >= 3

    def suggest(self, state, g, p):
        return [s for part in self.parts(g) for s in Tower().suggest(state, part, "any")]


class TwoTowers(Structure):
    key = "two-towers"
    min_size = 3

    def __init__(self, min_size: int | None = None, onto_standing: bool = False):
        """``onto_standing``: a moved block must end on a block of a tower standing on the table
        and no taller than the taller of the two wanted towers (the library's two-towers; by
        default being on a block is enough)."""
        super().__init__(min_size)
        self.onto_standing = onto_standing

    def sentence(self, subject, p):
        return f"{subject} are stacked into two towers of (nearly) equal height"

    def holds(self, f, g, p):
        t = _towers(f, g)
        return len(t) == 2 and (len(t[0]), len(t[1])) == ((len(g) + 1) // 2, len(g) // 2)

    def score(self, f, g, p):
        t = _towers(f, g)
        want = ((len(g) + 1) // 2, len(g) // 2)
        got = sum(min(len(x), w) for x, w in zip(t[:2], want, strict=False))
        return got / len(g) if len(t) >= 2 else min(len(t[0]) if t else 0, want[0]) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        if not self.onto_standing or fa.below[b] is None:
            return fa.below[b] is not None
        tower = next((t for t in _towers(fa, g) if b in t), None)
        return tower is not None and len(tower) <= (len(g) + 1) // 2

    def suggest(self, state, g, p):
        t = _towers(facts(state), g)
        return [PutOn(block=b, target=tower[-1]) for tower in t[:2] for b in g if b not in tower]


class TwoTowersAnyHeights(Structure):
    """Two towers of any heights, each of at least two blocks; scored by the share of blocks in
    the two tallest such towers (TwoTowers: nearly equal heights). Not registered (see InCell):
    the bayes grammar's two towers."""

    key = "two-towers-any-heights"
    min_size = 4

    def sentence(self, subject, p):
        return f"{subject} are stacked into two towers (any heights, at least two blocks each)"

    def holds(self, f, g, p):
        t = _towers(f, g)
        return len(t) == 2 and all(len(x) >= 2 for x in t) and sum(map(len, t)) == len(g)

    def _in_two(self, f, g) -> set[str]:
        return {b for x in _towers(f, g)[:2] if len(x) >= 2 for b in x}

    def score(self, f, g, p):
        return len(self._in_two(f, g)) / len(g) if g else 1.0

    def moved_ok(self, fb, fa, g, b, p):
        return b in self._in_two(fa, g)

    def suggest(self, state, g, p):
        return TwoTowers().suggest(state, g, p)


class TowerOnBlock(Structure):
    """One tower whose bottom block is the named one, standing on the table or in a bowl (Tower:
    on the table, any bottom block). Not registered (see InCell): the bayes grammar's tower on a
    block. A lone block is judged as in Tower with ``lone_flat``."""

    key = "tower-on"
    params = COLOR_NAMES

    def sentence(self, subject, p):
        return f"{subject} are stacked into one tower on the {p} block"

    def _growing(self, f, g, p) -> list[list[str]]:
        """Towers anywhere that can become the tower: on the named block, or single blocks."""
        return [t for t in _towers(f, g, on_table=False) if t[0] == f"{p} block" or len(t) == 1]

    def holds(self, f, g, p):
        full = [t for t in _towers(f, g, on_table=False) if len(t) == len(g)]
        return bool(full) and full[0][0] == f"{p} block"

    def score(self, f, g, p):
        return max((len(t) for t in self._growing(f, g, p)), default=0) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        return fa.below[b] is not None or (len(g) == 1 and fa.flat(b))

    def possible(self, g, objects, p):
        return f"{p} block" in g and len(g) >= self.min_size

    def bases(self, f: Facts, g: Group, p: str) -> list[str]:
        """Where the tower can grow from: the named block, when it is the bottom of a group tower."""
        return [t[0] for t in _towers(f, g, on_table=False) if t[0] == f"{p} block"]

    def suggest(self, state, g, p):
        f = facts(state)
        return [PutOn(block=b, target=f.tower(base)[-1]) for base in self.bases(f, g, p)
                for b in g if b not in f.tower(base)]


class BottomOfTower(Structure):
    """The group stacked as the bottom of one tower standing on the table; blocks of other
    groups may stand on top (Tower: the tower is the group's alone). A block is placed when it
    is in the longest run of group blocks from the base of a standing tower (ties: the first
    of the towers, tallest first). Not registered (see InCell): the library's
    warm-in-bowls-cool-stacked stacks its cool blocks so."""

    key = "bottom-of-tower"
    min_size = 1

    def sentence(self, subject, p):
        return f"{subject} are stacked into one tower on the table, other blocks may stand on top"

    def run(self, f: Facts, g: Group) -> list[str]:
        towers = sorted((f.tower(b) for b in f.blocks if f.below[b] is None and b in f.on_table), key=len, reverse=True)
        best: list[str] = []
        for tower in towers:
            n = next((i for i, b in enumerate(tower) if b not in g), len(tower))
            if n > len(best):
                best = tower[:n]
        return best

    def holds(self, f, g, p):
        return len(self.run(f, g)) == len(g)

    def score(self, f, g, p):
        return len(self.run(f, g)) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        return b in self.run(fa, g)

    def suggest(self, state, g, p):
        run = self.run(facts(state), g)
        return [PutOn(block=b, target=run[-1]) for b in g if b not in run] if run else []


class OneBowl(Structure):
    key = "one-bowl"
    min_size = 2

    def __init__(self, min_size: int | None = None, into_used: bool = False):
        """``into_used``: a moved block must end in a bowl, one that already held another block of
        the group before the move when any did (the library's one-bowl; by default a fullest
        bowl after the move)."""
        super().__init__(min_size)
        self.into_used = into_used

    def sentence(self, subject, p):
        return f"{subject} all go together in one bowl"

    def _counts(self, f, g):
        c: dict[str, int] = {}
        for b in g:
            if (w := f.bowl_of[b]) is not None:
                c[w] = c.get(w, 0) + 1
        return c

    def holds(self, f, g, p):
        return f.bowl_of[g[0]] is not None and all(f.bowl_of[b] == f.bowl_of[g[0]] for b in g)

    def score(self, f, g, p):
        return max(self._counts(f, g).values(), default=0) / len(g)

    def fullest(self, f: Facts, g: Group) -> str | None:
        """The bowl holding the most blocks of the group (ties: the first in the state), None
        without bowls."""
        c = self._counts(f, g)
        return max(f.bowls, key=lambda w: (c.get(w, 0), -f.bowls.index(w)), default=None)

    def moved_ok(self, fb, fa, g, b, p):
        if self.into_used:
            used = {fb.bowl_of[o] for o in g if o != b} - {None}
            return fa.bowl_of[b] is not None and (not used or fa.bowl_of[b] in used)
        c = self._counts(fa, g)
        return fa.bowl_of[b] is not None and c[fa.bowl_of[b]] == max(c.values())

    def possible(self, g, objects, p):
        return len(g) >= self.min_size and any(kind_of(o) == "bowl" for o in objects)

    def suggest(self, state, g, p):
        c = self._counts(facts(state), g)
        bowls = sorted(state.bowls, key=lambda w: -c.get(w, 0))
        return [PutIn(block=b, bowl=w) for w in bowls for b in g]


class EachBlock(Structure):
    """A structure each block of the group meets on its own (``block_ok``): it holds when all
    do, scores the share that do, and a move is fine when the moved block does."""

    def block_ok(self, f: Facts, g: Group, b: str) -> bool:
        raise NotImplementedError

    def holds(self, f, g, p):
        return all(self.block_ok(f, g, b) for b in g)

    def score(self, f, g, p):
        return sum(self.block_ok(f, g, b) for b in g) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        return self.block_ok(fa, g, b)


class SeparateBowls(EachBlock):
    key = "separate-bowls"
    min_size = 1

    def __init__(self, min_size: int | None = None, at_most: int = 1):
        """``at_most``: blocks of the group a bowl may hold (the dev suite's at most two per bowl;
        by default one block per bowl)."""
        super().__init__(min_size)
        self.at_most = at_most

    def sentence(self, subject, p):
        if self.at_most != 1:
            return f"{subject} go in bowls, at most {NUMBER.get(str(self.at_most), self.at_most)} blocks per bowl"
        return f"{subject} go in bowls, one block per bowl"

    def block_ok(self, f, g, b):
        w = f.bowl_of[b]
        if self.at_most != 1:
            return w is not None and sum(f.bowl_of[o] == w for o in g) <= self.at_most
        return w is not None and not any(o != b and f.bowl_of[o] == w for o in g)

    def possible(self, g, objects, p):
        return 1 <= len(g) <= self.at_most * sum(kind_of(o) == "bowl" for o in objects)

    def suggest(self, state, g, p):
        f = facts(state)
        used = {f.bowl_of[b] for b in g}
        return [PutIn(block=b, bowl=w) for b in g if not self.block_ok(f, g, b) for w in state.bowls if w not in used]


class Cluster(Structure):
    key = "cluster"

    def __init__(self, min_size: int | None = None, touching: bool = False, loaded: bool = False):
        """``touching``: a moved block must end next to another flat block of the group, unless
        the group is that one block (the bayes grammar's cluster). ``loaded``: a block of the
        group only has to rest on the table, another may stand on it (the dev suite's blocks
        together; by default the blocks are flat, nothing on them)."""
        super().__init__(min_size)
        self.touching = touching
        self.loaded = loaded

    def member(self, f: Facts, b: str) -> bool:
        return _rests_on_table(f, b) if self.loaded else _flat(f, b)

    def sentence(self, subject, p):
        return f"{subject} are grouped together on the table, each touching another"

    def _comp(self, f, g, start):
        seen, todo = {start}, [start]
        while todo:
            a = todo.pop()
            for o in g:
                if o not in seen and self.member(f, o) and f.next_to(a, o):
                    seen.add(o)
                    todo.append(o)
        return seen

    def holds(self, f, g, p):
        return all(self.member(f, b) for b in g) and len(self._comp(f, g, g[0])) == len(g)

    def score(self, f, g, p):
        return max((len(self._comp(f, g, b)) for b in g if self.member(f, b)), default=0) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        if not self.touching:
            return self.member(fa, b)
        return self.member(fa, b) and (len(g) == 1 or any(o != b and self.member(fa, o) and fa.next_to(b, o) for o in g))

    def suggest(self, state, g, p):
        f = facts(state)
        flat = [b for b in g if self.member(f, b)]
        if not flat:
            return []
        core = max((self._comp(f, g, b) for b in flat), key=len)
        # in the group's order: iterating the set would follow Python's per-process string hashing
        return [PutNextTo(block=b, target=t) for b in g if b not in core for t in g if t in core]


CORNERS = ("back left corner", "back right corner", "front left corner", "front right corner")


class Corners(EachBlock):
    key = "corners"
    min_size = 1

    def sentence(self, subject, p):
        return f"{subject} go on the table, each in a different corner"

    def corner(self, f, b):
        if b not in f.on_table or f.below[b] is not None:
            return None
        return next((c for c in CORNERS if in_region(f, b, c)), None)

    def block_ok(self, f, g, b):
        c = self.corner(f, b)
        return c is not None and all(self.corner(f, o) != c for o in g if o != b)

    def possible(self, g, objects, p):
        return 1 <= len(g) <= 4

    def suggest(self, state, g, p):
        f = facts(state)
        taken = {self.corner(f, o) for o in g}
        out: list[Skill] = []
        for b in g:
            if not self.block_ok(f, g, b):
                for c in CORNERS:
                    if c not in taken:
                        out += free_points(state, region_points(c), b, 3)
        return out


class SameCorner(Structure):
    """The whole group in one and the same corner cell of the table, any corner, blocks stacked
    or in a bowl there included; scored by the fullest corner; a moved block must end in a
    fullest corner. Not registered (see InCell): Placed(Cluster) "a-corner" also wants a group
    flat on the table and touching. The dev suite's gathering in one corner."""

    key = "same-corner"
    min_size = 1

    def sentence(self, subject, p):
        return f"{subject} all go in one corner of the table"

    def counts(self, f: Facts, g: Group) -> dict[str, int]:
        return {c: sum(f.cell[b] == c for b in g) for c in CORNER_CELL.values()}

    def holds(self, f, g, p):
        return max(self.counts(f, g).values()) == len(g)

    def score(self, f, g, p):
        return max(self.counts(f, g).values()) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        c = self.counts(fa, g)
        return c.get(fa.cell[b], 0) >= max(c.values())


def bowl_counts(f: Facts, g: Group) -> dict[str, int]:
    """How many blocks of the group each bowl of the state holds (0 for an empty bowl)."""
    c = dict.fromkeys(f.bowls, 0)
    for b in g:
        if (w := f.bowl_of[b]) is not None:
            c[w] += 1
    return c


class EachBowl(Structure):
    """Every bowl of the scene holds exactly ``n`` blocks of the group (the rest stay out)."""

    key = "each-bowl"
    params = ("1", "2")
    min_size = 1

    def sentence(self, subject, p):
        return f"every bowl holds exactly {NUMBER[p]} of {subject}"

    def _counts(self, f, g):
        return bowl_counts(f, g)

    def holds(self, f, g, p):
        return bool(f.bowls) and all(n == int(p) for n in self._counts(f, g).values())

    def score(self, f, g, p):
        c = self._counts(f, g)
        return sum(min(n, int(p)) - max(n - int(p), 0) for n in c.values()) / max(len(c) * int(p), 1)

    def moved_ok(self, fb, fa, g, b, p):
        w = fa.bowl_of[b]
        return w is None or self._counts(fa, g)[w] <= int(p)

    def possible(self, g, objects, p):
        bowls = sum(kind_of(o) == "bowl" for o in objects)
        return bowls >= 1 and len(g) >= bowls * int(p)

    def suggest(self, state, g, p):
        f = facts(state)
        c = self._counts(f, g)
        out: list[Skill] = []
        for w, n in c.items():
            if n > int(p):
                out += [s for b in g if f.bowl_of[b] == w and f.clear(b) for s in OnTable().targets(state, b, "")[:4]]
        short = [w for w, n in c.items() if n < int(p)]
        return out + [PutIn(block=b, bowl=w) for w in short for b in g if f.bowl_of[b] is None]


class AroundBowl(Structure):
    """Every block of the group on the table right next to one and the same bowl."""

    key = "around-bowl"
    min_size = 1

    def __init__(self, min_size: int | None = None, loaded: bool = False):
        """``loaded``: a block around the bowl only has to rest on the table, another may stand
        on it (the dev suite's blocks around a bowl; by default flat, nothing on it)."""
        super().__init__(min_size)
        self.loaded = loaded

    def sentence(self, subject, p):
        return f"{subject} stand on the table around one bowl, each right next to it"

    def member(self, f: Facts, b: str) -> bool:
        return _rests_on_table(f, b) if self.loaded else f.flat(b)

    def _best(self, f, g):
        return max(((sum(self.member(f, b) and f.next_to(b, w) for b in g), w) for w in f.bowls), default=(0, None))

    def target(self, f: Facts, g: Group) -> str | None:
        """The bowl with the most blocks of the group around it (ties: the first in the state),
        None without bowls."""
        return max(f.bowls, key=lambda w: (sum(self.member(f, b) and f.next_to(b, w) for b in g), -f.bowls.index(w)),
                   default=None)

    def block_ok(self, f: Facts, g: Group, b: str) -> bool:
        """Is ``b`` around the bowl the group gathers at?"""
        w = self.target(f, g)
        return w is not None and self.member(f, b) and f.next_to(b, w)

    def holds(self, f, g, p):
        return self._best(f, g)[0] == len(g)

    def score(self, f, g, p):
        return self._best(f, g)[0] / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        return self.member(fa, b) and any(fa.next_to(b, w) for w in fa.bowls)

    def possible(self, g, objects, p):
        return any(kind_of(o) == "bowl" for o in objects) and len(g) <= 4

    def suggest(self, state, g, p):
        f = facts(state)
        n, best = self._best(f, g)
        bowls = [best] + [w for w in state.bowls if w != best] if best else list(state.bowls)
        return [PutNextTo(block=b, target=w, side=s) for w in bowls[:2] for b in g
                if not (f.flat(b) and f.next_to(b, w)) for s in ("nearest", "left", "right", "front", "behind")]


class GroupsByClass(Structure):
    """Two groups on the table: the warm-coloured blocks together, the cool-coloured ones
    together, and no warm block touching a cool one."""

    key = "groups-by-class"
    min_size = 3

    def sentence(self, subject, p):
        return f"{subject} form two separate groups on the table, the warm-coloured ones together and the cool-coloured ones together"

    def holds(self, f, g, p):
        parts = TowersByClass.parts(g)
        return (len(parts) == 2 and all(Cluster().holds(f, part, "") for part in parts)
                and not any(f.next_to(a, b) for a in parts[0] for b in parts[1]))

    def score(self, f, g, p):
        parts = TowersByClass.parts(g)
        touching = sum(f.next_to(a, b) for a in parts[0] for b in parts[-1]) if len(parts) == 2 else 0
        s = sum(Cluster().score(f, part, "") * len(part) for part in parts) / len(g)
        return max(s - touching / len(g), 0.0)

    def moved_ok(self, fb, fa, g, b, p):
        parts = TowersByClass.parts(g)
        other = next((x for x in parts if b not in x), ())
        return fa.flat(b) and not any(fa.next_to(b, o) for o in other)

    def possible(self, g, objects, p):
        return len(TowersByClass.parts(g)) == 2 and len(g) >= 3

    def suggest(self, state, g, p):
        return [s for part in TowersByClass.parts(g) for s in Cluster().suggest(state, part, "")]


class ClassGroupsApart(Structure):
    """The warm-coloured blocks of the group together and the cool-coloured ones together on the
    table, a block touching one of the other class counting for neither; scored by the largest
    group of each class. A moved block must rest apart from the other class and next to a block
    of its own (when it has one). Not registered (see InCell): GroupsByClass wants flat blocks
    and scores a penalty per touching pair. The dev suite's warm and cool groups."""

    key = "class-groups-apart"
    min_size = 3

    def sentence(self, subject, p):
        return (f"{subject} form two groups on the table, the warm-coloured ones together and the "
                "cool-coloured ones together, none touching one of the other kind")

    @staticmethod
    def apart(f: Facts, g: Group, b: str) -> bool:
        """On the table (another block may stand on it), touching no block of the other class."""
        return _rests_on_table(f, b) and not any(f.next_to(b, o) for o in g if _class(o) != _class(b))

    def largest(self, f: Facts, g: Group, part: Group) -> int:
        left = [b for b in part if self.apart(f, g, b)]
        best = 0
        while left:
            group, todo = {left[0]}, [left[0]]
            while todo:
                a = todo.pop()
                for o in left:
                    if o not in group and f.next_to(a, o):
                        group.add(o)
                        todo.append(o)
            left = [b for b in left if b not in group]
            best = max(best, len(group))
        return best

    def placed(self, f: Facts, g: Group) -> int:
        return sum(self.largest(f, g, part) for part in TowersByClass.parts(g))

    def holds(self, f, g, p):
        return self.placed(f, g) == len(g)

    def score(self, f, g, p):
        return self.placed(f, g) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        kin = [o for o in g if o != b and _class(o) == _class(b)]
        return self.apart(fa, g, b) and (not kin or any(fa.next_to(b, o) for o in kin))

    def possible(self, g, objects, p):
        return len(TowersByClass.parts(g)) == 2 and len(g) >= 3

    def suggest(self, state, g, p):
        return GroupsByClass().suggest(state, g, p)


PLACES = ("back-edge", "front-edge", "left-edge", "right-edge", "middle", "a-corner", "by-a-bowl")
PLACE_WORDS = {"back-edge": "along the back edge of the table", "front-edge": "along the front edge of the table",
               "left-edge": "along the left edge of the table", "right-edge": "along the right edge of the table",
               "middle": "in the middle of the table", "a-corner": "in one corner of the table",
               "by-a-bowl": "right next to one bowl"}
EDGE = 0.1  # "along an edge": centres within 10 cm of it (the workspace is 60 × 60 cm)
PLACE_AREA = {"back-edge": lambda xy: xy[1] > -0.2 - EDGE, "front-edge": lambda xy: xy[1] < -0.8 + EDGE,
              "left-edge": lambda xy: xy[0] < -0.3 + EDGE, "right-edge": lambda xy: xy[0] > 0.3 - EDGE,
              "middle": lambda xy: abs(xy[0]) < 0.15 and abs(xy[1] + 0.5) < 0.1}


@memoized(size=64, why="a place's name (PLACE_AREA, a constant); the grid never changes")
def place_points(place: str) -> tuple[tuple[float, float], ...]:
    """Grid points of a place, nearest its centre first."""
    return _area_points(PLACE_AREA[place])


class Placed(Structure):
    """A structure at a place: "a row along the back edge", "a tower next to a bowl", "grouped in
    one corner". Parameters ``order`` or ``order@place``; their bits are a small grammar: one bit
    for "in an order", then which order (uniform); one bit for "at a place", then which place."""

    def __init__(self, inner: Structure, orders: tuple[str, ...]):
        self.inner = inner
        self.key = inner.key
        self.min_size = inner.min_size
        self.orders = orders
        self.params = orders + tuple(f"{o}@{pl}" for o in orders for pl in PLACES)

    def param_bits(self, p):
        if p is None:
            return math.log2(len(self.params))
        order, _, place = p.partition("@")
        ordered = 0.0 if len(self.orders) == 1 else 1 + (math.log2(len(self.orders) - 1) if order != "any" else 0)
        return ordered + 1 + (math.log2(len(PLACES)) if place else 0)

    def sentence(self, subject, p):
        order, _, place = p.partition("@")
        return self.inner.sentence(subject, order) + (f", {PLACE_WORDS[place]}" if place else "")

    @staticmethod
    def _share(f: Facts, g: Group, place: str) -> float:
        """Share of the group standing (itself or its tower's base) on the table at the place;
        for a corner or a bowl: the same corner / bowl for all."""
        bases = [f.base(b) for b in g]
        down = [b for b in bases if b in f.on_table and f.bowl_of[b] is None]
        if place in PLACE_AREA:
            return sum(PLACE_AREA[place](f.xy[b]) for b in down) / len(g)
        if place == "a-corner":
            return max((sum(in_region(f, b, c) for b in down) for c in CORNERS), default=0) / len(g)
        return max((sum(f.next_to(b, w) for b in down) for w in f.bowls), default=0) / len(g)

    def holds(self, f, g, p):
        return self.judge(f, g, p)[0]

    def score(self, f, g, p):
        return self.judge(f, g, p)[1]

    def judge(self, f, g, p):
        """(holds, score): the inner shape's, and for a place also all the group there (the
        score the mean of the two). The inner verdict is shared by every place and the place's
        share by every shape and order (memoised on the state: the hot path)."""
        order, _, place = p.partition("@")
        inner = self.inner_judge(f, g, order)
        if not place:
            return inner
        share = self.share(f, g, place)
        return inner[0] and share == 1.0, (inner[1] + share) / 2

    def inner_judge(self, f: Facts, g: Group, order: str) -> tuple[bool, float]:
        """(holds, score) of the inner shape in ``order`` (memoised on the state)."""
        k = ("placed-inner", self.key, order, g)
        inner = f.memo.get(k)
        if inner is None:
            inner = f.memo[k] = (self.inner.holds(f, g, order), float(self.inner.score(f, g, order)))
        return inner

    @classmethod
    def share(cls, f: Facts, g: Group, place: str) -> float:
        """Share of the group at the place (``_share``), memoised on the state."""
        k = ("placed-share", place, g)
        share = f.memo.get(k)
        if share is None:
            share = f.memo[k] = cls._share(f, g, place)
        return share

    def moved_ok(self, fb, fa, g, b, p):
        order, _, place = p.partition("@")
        if not self.inner.moved_ok(fb, fa, g, b, order):
            return False
        return (not place or self.share(fa, (b,), place) == 1.0
                or self.share(fa, g, place) >= self.share(fb, g, place))

    def possible(self, g, objects, p):
        order, _, place = p.partition("@")
        return self.inner.possible(g, objects, order) and (place != "by-a-bowl" or any(
            kind_of(o) == "bowl" for o in objects))

    def suggest(self, state, g, p):
        order, _, place = p.partition("@")
        inner = self.inner.suggest(state, g, order)
        if not place:
            return inner
        f = facts(state)
        here = {b for b in g if self._share(f, (f.base(b),), place) == 1.0}
        if here:  # grow the structure from the part already in place: moves onto / next to it first
            onto = [st for st in inner if getattr(st, "target", None) in here]
            return onto + [st for st in inner if st not in onto]
        first = sorted(g, key=_order_key(order)) if order not in ("any", "") else list(g)
        movers = [b for b in first if f.clear(b)][:2]
        if place in PLACE_AREA:
            return [s for b in movers for s in free_points(state, place_points(place), b, 6)] + inner
        if place == "a-corner":
            return [s for b in movers for c in CORNERS for s in free_points(state, region_points(c), b, 2)] + inner
        return [PutNextTo(block=b, target=w, side=sd) for b in movers for w in state.bowls
                for sd in ("nearest", "left", "right", "front", "behind")] + inner


for _node in (Placed(Row(), ORDERS), Placed(Column(), ORDERS), Placed(Tower(), ORDERS), TowersByClass(), TwoTowers(),
              OneBowl(), SeparateBowls(), Placed(Cluster(), ("",)), Corners(), EachBowl(), AroundBowl(),
              GroupsByClass()):
    register(_node)
