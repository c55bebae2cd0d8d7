"""Node types of language 2: what requests of the corpus (data/requests) needed.

The language grows by a stated rule: a construct that at least 3 requests the language could
not express need joins it (data/requests/README.md lists each with its requests). Every node
here has ``since = 2``, so language 1 — in which earlier episodes ran — stays as it was.

- selectors ``colours`` / ``all-but-colours``: the blocks of two named colours, or the others
  ("the orange and yellow ones");
- relations ``in-bowl-at`` (the bowl at a place: leftmost, nearest the front, nearest the
  middle, …), ``side-of-bowls`` (left of / in front of … every bowl), ``table-part`` (in any
  corner, at any edge), and the conditional ``in-the-bowl-if-there``, ``on-the-block-if-there``,
  ``next-to-if-there``, ``side-if-there`` (the clause holds on a day the named object is absent),
  and ``in-bowl-else`` (in a bowl, or else at a place: where the blocks left over go);
- structures ``stacks`` (no stack higher than 2 / 3, or stacked in pairs), ``tower-by-shade``
  and ``row-by-shade`` (darkest first, by the palette's lightness), ``by-each-bowl`` (one block
  right next to each bowl, on a side) and ``two-bowls`` (the blocks in one bowl, the others
  together in another).
"""

from __future__ import annotations

from itertools import combinations

# language 1's node types first: registration order is enumeration order (selectors: nothing
# else here imports them)
import activeintent.goals.selectors  # noqa: F401,I001
from activeintent.goals.facts import Facts, facts
from activeintent.goals.nodes import Group, Relation, Selector, Structure, register
from activeintent.goals.planning import GRID, free_points, nearest_points
from activeintent.goals.relations import (
    REGIONS,
    SIDE_WORDS,
    Beside,
    InNamedBowl,
    NextTo,
    OnNamedBlock,
    OnTable,
    in_region,
    region_points,
)
from activeintent.goals.structures import (
    CORNERS,
    ORDER_KEYS,
    PLACE_AREA,
    Placed,
    Row,
    Tower,
    _towers,
    bowl_counts,
)
from activeintent.world import PutIn, PutNextTo, PutOn, Skill
from activeintent.world.colors import COLOR_NAMES, COLORS
from activeintent.world.scene import color_of, kind_of
from activeintent.world.skills import SIDES

VERSION = 2

# ---- selectors ------------------------------------------------------------------------------

COLOUR_PAIRS = tuple(f"{a}+{b}" for a, b in combinations(COLOR_NAMES, 2))


class Colours(Selector):
    """The blocks of either of two named colours ("the orange and yellow blocks")."""

    key = "colours"
    params = COLOUR_PAIRS
    since = VERSION

    def noun(self, p):
        a, b = p.split("+")
        return f"{a} or {b} block"

    def pick(self, block, bowls, p):
        return color_of(block) in p.split("+")


class AllButColours(Selector):
    """Every block but those of two named colours."""

    key = "all-but-colours"
    params = COLOUR_PAIRS
    since = VERSION

    def noun(self, p):
        a, b = p.split("+")
        return f"block neither {a} nor {b}"

    def pick(self, block, bowls, p):
        return color_of(block) not in p.split("+")


# ---- relations ------------------------------------------------------------------------------

# A bowl picked by where it stands: the extreme one along an axis, or the one nearest the middle.
BOWL_PLACES = {"leftmost": (0, -1), "rightmost": (0, 1), "front-most": (1, -1), "back-most": (1, 1), "central": None}
BOWL_PLACE_WORDS = {"leftmost": "the leftmost bowl", "rightmost": "the rightmost bowl",
                    "front-most": "the bowl nearest the front edge", "back-most": "the bowl nearest the back edge",
                    "central": "the bowl nearest the middle of the table"}
MIDDLE = (0.0, -0.5)  # the table's centre (front = smaller y)


def bowl_at(xy: dict[str, tuple[float, float]], bowls, place: str) -> str | None:
    """The bowl at ``place`` among ``bowls`` (ties: the first), None without bowls."""
    bowls = list(bowls)
    if not bowls:
        return None
    how = BOWL_PLACES[place]
    if how is None:
        return min(bowls, key=lambda w: (xy[w][0] - MIDDLE[0]) ** 2 + (xy[w][1] - MIDDLE[1]) ** 2)
    axis, sign = how
    return max(bowls, key=lambda w: sign * xy[w][axis])


class InBowlAt(Relation):
    """In the bowl that stands at a place of the table (the leftmost, the one nearest the front…)."""

    key = "in-bowl-at"
    params = tuple(BOWL_PLACES)
    since = VERSION

    def phrase(self, p):
        return f"in {BOWL_PLACE_WORDS[p]}"

    def ok(self, f, b, p):
        w = f.bowl_of[b]
        return w is not None and w == bowl_at(f.xy, f.bowls, p)

    def possible(self, b, objects, p):
        return any(kind_of(o) == "bowl" for o in objects)

    def targets(self, state, b, p):
        w = bowl_at({o: state.pos(o)[:2] for o in state.bowls}, state.bowls, p)
        return [] if w is None else [PutIn(block=b, bowl=w)]


class NextToBowlAt(Relation):
    """Right next to the bowl that stands at a place of the table (not in a bowl)."""

    key = "next-to-bowl-at"
    params = tuple(BOWL_PLACES)
    since = VERSION

    def phrase(self, p):
        return f"right next to {BOWL_PLACE_WORDS[p]} (not in a bowl)"

    def ok(self, f, b, p):
        w = bowl_at(f.xy, f.bowls, p)
        return w is not None and f.bowl_of[b] is None and f.next_to(b, w)

    def possible(self, b, objects, p):
        return any(kind_of(o) == "bowl" for o in objects)

    def targets(self, state, b, p):
        w = bowl_at({o: state.pos(o)[:2] for o in state.bowls}, state.bowls, p)
        return [] if w is None else [PutNextTo(block=b, target=w, side=sd)
                                     for sd in ("nearest", "left", "right", "front", "behind")]


class SideOfBowls(Relation):
    """Entirely on one side of every bowl (left of / right of / in front of / behind all of
    them), not in a bowl."""

    key = "side-of-bowls"
    params = SIDES
    since = VERSION

    def phrase(self, p):
        return f"{SIDE_WORDS[p]} every bowl (not in a bowl)"

    def ok(self, f, b, p):
        return (f.bowl_of[b] is None and bool(f.bowls)
                and all(Beside.beyond(f.xy[b], f.xy[w], w, p) for w in f.bowls))

    def possible(self, b, objects, p):
        return any(kind_of(o) == "bowl" for o in objects)

    def targets(self, state, b, p):
        bowls = list(state.bowls)
        if not bowls:
            return []
        pts = [q for q in GRID if all(Beside.beyond(q, state.pos(w)[:2], w, p) for w in bowls)]
        return free_points(state, nearest_points(state, b, pts), b, 8)


EDGES = ("back-edge", "front-edge", "left-edge", "right-edge")
TABLE_PARTS = {"a-corner": "in a corner of the table", "an-edge": "at an edge of the table"}


def at_part(f: Facts, b: str, part: str) -> bool:
    if part == "a-corner":
        return any(in_region(f, b, c) for c in CORNERS)
    return any(PLACE_AREA[e](f.xy[b]) for e in EDGES)


class TablePart(Relation):
    """On the table in any of its corners, or at any of its edges (not in a bowl)."""

    key = "table-part"
    params = tuple(TABLE_PARTS)
    since = VERSION

    def phrase(self, p):
        return f"{TABLE_PARTS[p]} (any one; not in a bowl)"

    def ok(self, f, b, p):
        return f.bowl_of[b] is None and b in f.on_table and f.below[b] is None and at_part(f, b, p)

    def targets(self, state, b, p):
        if p == "a-corner":
            pts = [q for c in CORNERS for q in region_points(c)[:3]]
        else:
            pts = [q for q in GRID if any(PLACE_AREA[e](q) for e in EDGES)]
        return free_points(state, nearest_points(state, b, pts), b, 8)


class IfThere(Relation):
    """``inner`` on a day the object it names is on the table; on a day it is not, the clause
    holds whatever its quantifier ("the green blocks in the green bowl, if there is one")."""

    vacuous_without_ref = True
    since = VERSION

    def __init__(self, inner: Relation):
        self.inner = inner
        self.key = f"{inner.key}-if-there"
        self.params = tuple(p for p in inner.params if inner.refers(p) is not None)

    def phrase(self, p):
        return f"{self.inner.phrase(p)}, if that one is on the table (else anywhere)"

    def refers(self, p):
        return self.inner.refers(p)

    def ok(self, f, b, p):
        return self.inner.ok(f, b, p)

    def same_ok(self, p):
        return self.inner.same_ok(p)

    def possible(self, b, objects, p):
        return self.refers(p) not in objects or self.inner.possible(b, objects, p)

    def targets(self, state, b, p):
        return self.inner.targets(state, b, p)


ELSE_PLACES = {**{r: f"in the {r} of the table" for r in REGIONS}, "a-corner": "in a corner of the table",
               "an-edge": "at an edge of the table", "next-to-a-bowl": "right next to a bowl"}


class InBowlElse(Relation):
    """In a bowl, or else (a block left over when the bowls are taken) at a place on the table:
    "one block per bowl, the extras on the left side"."""

    key = "in-bowl-else"
    params = tuple(ELSE_PLACES)
    since = VERSION

    def phrase(self, p):
        return f"in a bowl, or else {ELSE_PLACES[p]} (not stacked)"

    def ok(self, f, b, p):
        if f.bowl_of[b] is not None:
            return True
        if b not in f.on_table or f.below[b] is not None:
            return False
        if p == "next-to-a-bowl":
            return any(f.next_to(b, w) for w in f.bowls)
        if p in TABLE_PARTS:
            return at_part(f, b, p)
        return in_region(f, b, p)

    def possible(self, b, objects, p):
        return True

    def targets(self, state, b, p):
        out: list[Skill] = [PutIn(block=b, bowl=w) for w in state.bowls]
        if p == "next-to-a-bowl":
            return out + [PutNextTo(block=b, target=w) for w in state.bowls]
        if p in TABLE_PARTS:
            return out + TablePart().targets(state, b, p)
        return out + free_points(state, region_points(p), b, 8)


# ---- structures -----------------------------------------------------------------------------

STACKS = {"max-2": "no stack of them is more than two blocks high",
          "max-3": "no stack of them is more than three blocks high",
          "pairs": "they are stacked in pairs, one block on another (an odd one out stands alone)"}


def _height(f: Facts, b: str) -> int:
    return len(f.tower(f.base(b)))


class Stacks(Structure):
    """Low stacks: every block of the group in a stack (in a bowl or on the table) of at most
    2 / 3 blocks; or ``pairs``: towers of exactly two group blocks on the table, an odd one out
    standing alone."""

    key = "stacks"
    params = tuple(STACKS)
    min_size = 1
    since = VERSION

    def sentence(self, subject, p):
        if p == "pairs":
            return f"{subject} are stacked in pairs on the table, one block on another (an odd one out stands alone)"
        return f"{subject} stand in stacks no more than {'two' if p == 'max-2' else 'three'} blocks high"

    def _pairs(self, f: Facts, g: Group) -> tuple[int, list[str]]:
        """(blocks in towers of exactly two of the group, the blocks left)."""
        paired = [b for t in _towers(f, g) if len(t) == 2 for b in t]
        return len(paired), [b for b in g if b not in paired]

    def holds(self, f, g, p):
        if p == "pairs":
            n, rest = self._pairs(f, g)
            return len(rest) == len(g) % 2 and all(f.below[b] is None and f.above[b] is None for b in rest)
        cap = 2 if p == "max-2" else 3
        return all(_height(f, b) <= cap for b in g)

    def score(self, f, g, p):
        if p == "pairs":
            return self._pairs(f, g)[0] / (len(g) - len(g) % 2 or 1)
        cap = 2 if p == "max-2" else 3
        return sum(_height(f, b) <= cap for b in g) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        if p == "pairs":
            under = fa.below[b]
            return (under is None and fa.above[b] is None) or (
                under in g and under in fa.on_table and fa.below[under] is None and fa.above[b] is None)
        return _height(fa, b) <= (2 if p == "max-2" else 3)

    def possible(self, g, objects, p):
        return len(g) >= (2 if p == "pairs" else 1)

    def suggest(self, state, g, p):
        f = facts(state)
        out: list[Skill] = []
        if p == "pairs":
            n, rest = self._pairs(f, g)
            free = [b for b in rest if f.clear(b)]
            bases = [b for b in free if b in f.on_table and f.below[b] is None and f.above[b] is None]
            for base in bases[:2]:
                out += [PutOn(block=b, target=base) for b in free if b != base]
            for b in rest:  # a block stacked on another or in a tower too tall: off to the table first
                if f.below[b] is not None or f.above[b] is not None:
                    out += OnTable().targets(state, b, "")[:2]
            return out
        cap = 2 if p == "max-2" else 3
        for b in g:
            if _height(f, b) > cap and f.clear(b):
                out += OnTable().targets(state, b, "")[:4]
        return out


def _linear(c: float) -> float:
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


# Darkness: the relative luminance of the colour as the table shows it (sRGB palette, linearised).
LIGHTNESS = {c: 0.2126 * _linear(r) + 0.7152 * _linear(g) + 0.0722 * _linear(b) for c, (r, g, b) in COLORS.items()}
SHADES = ("dark-first", "light-first")
SHADE_WORDS = {"dark-first": "the darkest colour first", "light-first": "the lightest colour first"}


def shade_key(order: str):
    sign = 1 if order == "dark-first" else -1
    return lambda b: sign * LIGHTNESS[color_of(b)]


ORDER_KEYS.update({order: shade_key(order) for order in SHADES})


ORDER_KEYS["alphabetical"] = color_of  # by the colour's name, a to z
NAME_ORDERS = ("alphabetical",)
ORDER_PHRASES = {**SHADE_WORDS, "alphabetical": "in alphabetical order of the colours' names"}


def in_key_order(seq, order: str) -> bool:
    return list(seq) == sorted(seq, key=ORDER_KEYS[order])


class TowerByShade(Tower):
    """One tower, darkest at the bottom (or lightest), by the palette's lightness."""

    key = "tower-by-shade"
    params = SHADES
    since = VERSION

    def sentence(self, subject, p):
        return f"{subject} are stacked into one tower, {ORDER_PHRASES[p]} from the bottom up"

    def _ordered(self, f: Facts, g: Group, p: str) -> int:
        want = sorted(g, key=ORDER_KEYS[p])
        if f.below[want[0]] is not None or want[0] not in f.on_table:
            return 0
        chain = f.tower(want[0])
        n = 0
        while n < len(chain) and n < len(want) and chain[n] == want[n]:
            n += 1
        return n

    def holds(self, f, g, p):
        return self._ordered(f, g, p) == len(g) and f.above[sorted(g, key=ORDER_KEYS[p])[-1]] is None

    def score(self, f, g, p):
        return 1.0 if self.holds(f, g, p) else self._ordered(f, g, p) / len(g)

    def suggest(self, state, g, p):
        f = facts(state)
        want = sorted(g, key=ORDER_KEYS[p])
        n = self._ordered(f, g, p)
        if n == 0:
            return free_points(state, nearest_points(state, want[0]), want[0], 6)
        return [PutOn(block=want[n], target=want[n - 1])] if n < len(want) else []


class RowByShade(Row):
    """One left-to-right row, darkest colour at the left (or lightest)."""

    key = "row-by-shade"
    params = SHADES
    since = VERSION

    def sentence(self, subject, p):
        return (f"{subject} form one left-to-right row on the table, each next to its neighbour, "
                f"{ORDER_PHRASES[p]} left to right")

    def line(self, f, blocks, p):
        if not super().line(f, blocks, "any"):
            return False
        along = sorted(blocks, key=lambda b: f.xy[b][0])
        return in_key_order(along, p)

    def suggest(self, state, g, p):
        f = facts(state)
        want = sorted(g, key=ORDER_KEYS[p])
        k = max((n for n in range(1, len(want) + 1) if self.line(f, tuple(want[:n]), p)), default=0)
        if k == 0:
            return free_points(state, nearest_points(state, want[0]), want[0], 4)
        if k < len(want):
            return [PutNextTo(block=want[k], target=want[k - 1], side="right")]
        return []


class TowerByName(TowerByShade):
    """One tower in alphabetical order of the colours' names from the bottom up."""

    key = "tower-by-name"
    params = NAME_ORDERS


class RowByName(RowByShade):
    """One left-to-right row in alphabetical order of the colours' names."""

    key = "row-by-name"
    params = NAME_ORDERS


BY_BOWL_SIDES = ("next",) + SIDES


class ByEachBowl(Structure):
    """Every bowl has exactly one block of the group right next to it (on a side, or any), on
    the table: "a block in front of each bowl, like a name tag". The other blocks go anywhere."""

    key = "by-each-bowl"
    params = BY_BOWL_SIDES
    min_size = 1
    since = VERSION

    def sentence(self, subject, p):
        where = "right next to it" if p == "next" else f"right next to it, {SIDE_WORDS[p]} it"
        return f"every bowl has exactly one of {subject} on the table {where}"

    def at(self, f: Facts, b: str, w: str, p: str) -> bool:
        return (f.bowl_of[b] is None and b in f.on_table and f.below[b] is None and f.next_to(b, w)
                and (p == "next" or Beside.beyond(f.xy[b], f.xy[w], w, p)))

    def _counts(self, f: Facts, g: Group, p: str) -> dict[str, int]:
        return {w: sum(self.at(f, b, w, p) for b in g) for w in f.bowls}

    def holds(self, f, g, p):
        c = self._counts(f, g, p)
        return bool(c) and all(n == 1 for n in c.values())

    def score(self, f, g, p):
        c = self._counts(f, g, p)
        return sum(n == 1 for n in c.values()) / max(len(c), 1)

    def moved_ok(self, fb, fa, g, b, p):
        c = self._counts(fa, g, p)
        return all(n <= 1 for n in c.values())

    def possible(self, g, objects, p):
        bowls = sum(kind_of(o) == "bowl" for o in objects)
        return bowls >= 1 and len(g) >= bowls

    def suggest(self, state, g, p):
        f = facts(state)
        c = self._counts(f, g, p)
        used = {b for b in g for w in f.bowls if self.at(f, b, w, p)}
        free = [b for b in g if b not in used and f.clear(b)]
        side = "nearest" if p == "next" else p
        return [PutNextTo(block=b, target=w, side=side) for w, n in c.items() if n == 0 for b in free]


CAPS = {"max-2": 2, "max-3": 3}  # blocks a bowl may hold under a cap
LOADS = {"max-2": "no bowl holds more than two of them", "max-3": "no bowl holds more than three of them",
         "even": "they are all in bowls, spread evenly (no bowl holds two more than another)"}


class BowlLoad(Structure):
    """How the group fills the bowls: at most 2 / 3 in any bowl, or all in bowls spread evenly."""

    key = "bowl-load"
    params = tuple(LOADS)
    min_size = 1
    since = VERSION

    def sentence(self, subject, p):
        return f"{LOADS[p].replace('them', subject, 1).replace('they are', subject + ' are', 1)}"

    def _counts(self, f: Facts, g: Group) -> dict[str, int]:
        return bowl_counts(f, g)

    def holds(self, f, g, p):
        c = self._counts(f, g)
        if p == "even":
            return bool(c) and all(f.bowl_of[b] is not None for b in g) and max(c.values()) - min(c.values()) <= 1
        return all(n <= CAPS[p] for n in c.values())

    def score(self, f, g, p):
        c = self._counts(f, g)
        if p == "even":
            inside = sum(c.values()) / len(g)
            return inside if not c or max(c.values()) - min(c.values()) <= 1 else inside / 2
        return 1.0 - sum(max(n - CAPS[p], 0) for n in c.values()) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        w = fa.bowl_of[b]
        if p == "even":
            c = self._counts(fa, g)
            return w is not None and c[w] - 1 <= min(c.values())
        return w is None or self._counts(fa, g)[w] <= CAPS[p]

    def possible(self, g, objects, p):
        return p != "even" or any(kind_of(o) == "bowl" for o in objects)

    def suggest(self, state, g, p):
        f = facts(state)
        c = self._counts(f, g)
        out: list[Skill] = []
        if p == "even":
            order = sorted(state.bowls, key=lambda w: c[w])
            return [PutIn(block=b, bowl=w) for w in order[:1] for b in g if f.bowl_of[b] is None or c[f.bowl_of[b]] > c[w] + 1]
        cap = 2 if p == "max-2" else 3
        for w, n in c.items():
            if n > cap:
                out += [st for b in g if f.bowl_of[b] == w and f.clear(b) for st in OnTable().targets(state, b, "")[:3]]
                out += [PutIn(block=b, bowl=v) for b in g if f.bowl_of[b] == w for v in state.bowls if c[v] < cap]
        return out


class EvenHalves(Structure):
    """The group split evenly between the left and the right half of the table (counts differ by
    at most one), every block on the table."""

    key = "even-halves"
    params = ("",)
    min_size = 2
    since = VERSION

    def sentence(self, subject, p):
        return f"{subject} are split evenly between the left and the right half of the table (on the table, not in bowls)"

    def _sides(self, f: Facts, g: Group) -> tuple[int, int, int]:
        down = [b for b in g if f.bowl_of[b] is None and b in f.on_table]
        left = sum(f.xy[f.base(b)][0] < 0 for b in down)
        return left, len(down) - left, len(g) - len(down)

    def holds(self, f, g, p):
        left, right, off = self._sides(f, g)
        return off == 0 and abs(left - right) <= 1

    def score(self, f, g, p):
        left, right, off = self._sides(f, g)
        return (len(g) - off - max(abs(left - right) - 1, 0)) / len(g)

    def moved_ok(self, fb, fa, g, b, p):
        left, right, off = self._sides(fa, g)
        return fa.bowl_of[b] is None and abs(left - right) <= max(abs(self._sides(fb, g)[0] - self._sides(fb, g)[1]), 1)

    def suggest(self, state, g, p):
        f = facts(state)
        left, right, _ = self._sides(f, g)
        half = "left half" if left <= right else "right half"
        movers = [b for b in g if f.clear(b) and (f.bowl_of[b] is not None or (f.xy[b][0] < 0) != (half == "left half"))]
        return [st for b in movers for st in free_points(state, region_points(half), b, 4)]


class TwoBowls(Structure):
    """The group together in one bowl and every other block together in another bowl ("warm
    ones in one bowl, cool ones in another")."""

    key = "two-bowls"
    params = ("",)
    min_size = 1
    since = VERSION

    def sentence(self, subject, p):
        return f"{subject} all go together in one bowl, and every other block together in another bowl"

    @staticmethod
    def _one(f: Facts, blocks) -> str | None:
        ws = {f.bowl_of[b] for b in blocks}
        return next(iter(ws)) if len(ws) == 1 else None

    def holds(self, f, g, p):
        others = [b for b in f.blocks if b not in g]
        w = self._one(f, g)
        if w is None or not others:
            return False
        v = self._one(f, others)
        return v is not None and v != w

    def score(self, f, g, p):
        others = [b for b in f.blocks if b not in g]

        def fullest(blocks) -> tuple[int, str | None]:
            c: dict[str, int] = {}
            for b in blocks:
                if (w := f.bowl_of[b]) is not None:
                    c[w] = c.get(w, 0) + 1
            return max(((n, w) for w, n in c.items()), default=(0, None))

        n, w = fullest(g)
        m = max((sum(f.bowl_of[b] == v for b in others) for v in f.bowls if v != w), default=0)
        return (n + m) / max(len(g) + len(others), 1)

    def moved_ok(self, fb, fa, g, b, p):
        return fa.bowl_of[b] is not None

    def possible(self, g, objects, p):
        blocks = [o for o in objects if kind_of(o) == "block"]
        return sum(kind_of(o) == "bowl" for o in objects) >= 2 and len(blocks) > len(g)

    def suggest(self, state, g, p):
        f = facts(state)
        others = [b for b in f.blocks if b not in g]
        out: list[Skill] = []
        for w in state.bowls:
            for v in state.bowls:
                if v != w:
                    out += [PutIn(block=b, bowl=w) for b in g if f.bowl_of[b] != w]
                    out += [PutIn(block=b, bowl=v) for b in others if f.bowl_of[b] != v]
        return out


for _node in (Colours(), AllButColours(), InBowlAt(), SideOfBowls(), TablePart(),
              IfThere(InNamedBowl()), IfThere(OnNamedBlock()), IfThere(NextTo()), IfThere(Beside()), InBowlElse(), Stacks(),
              Placed(TowerByShade(), SHADES), Placed(RowByShade(), SHADES), Placed(TowerByName(), NAME_ORDERS),
              Placed(RowByName(), NAME_ORDERS), ByEachBowl(), TwoBowls(), BowlLoad(), EvenHalves(), NextToBowlAt()):
    _node.since = VERSION
    register(_node)
