"""Goals of the language: clauses (``Each``: a quantifier, a selector and a relation;
``Form``: a structure over a selected group), a goal of up to :data:`MAX_CLAUSES` clauses with
its sentence and description length L(z), parsing and the enumeration of every clause."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import permutations

from activeintent.goals.facts import Facts
from activeintent.goals.nodes import NODES, Group, Relation, Selector, Structure, nodes, spoken
from activeintent.goals.relations import OnTable
from activeintent.goals.structures import NUMBER
from activeintent.world import PutIn, Skill, WorldState
from activeintent.world.scene import kind_of

# ---- quantifiers ---------------------------------------------------------------------------

MAX_CLAUSES = 3  # a goal is a conjunction of 1–3 clauses
QUANTS = ("every", "none", "exactly-1", "exactly-2", "at-least-1", "at-least-2")
# The quantifier is a small grammar, uniform at each choice: every | none | a count; a count is
# "exactly" or "at least", then the number (1 or 2).
QUANT_BITS = {q: math.log2(3) + (0 if q in ("every", "none") else 2) for q in QUANTS}
REUSE_BITS = math.log2(3)  # a later clause's blocks: the same as the clause before | the others | named anew


def quant_holds(q: str, cnt, size):
    """Works on ints and on numpy arrays alike."""
    if q == "every":
        return cnt == size
    if q == "none":
        return cnt == 0
    n = int(q[-1])
    return cnt == n if q.startswith("exactly") else cnt >= n


def quant_score(q: str, cnt: int, size: int) -> float:
    """How close a count is to the quantifier (Python ints: one IEEE division per score, no
    numpy scalars; learners/lang/space.py computes the same scores for many clauses at once)."""
    size = max(size, 1)
    if q == "every":
        return cnt / size
    if q == "none":
        return 1.0 - cnt / size
    n = int(q[-1])
    if q.startswith("exactly"):
        return min(max(1.0 - abs(cnt - n) / max(size, n), 0.0), 1.0)
    return min(cnt, n) / n


# ---- clauses and goals ------------------------------------------------------------------------


def _groups(f: Facts) -> dict:
    g = f.memo.get("lang-groups")
    if g is None:
        g = f.memo["lang-groups"] = {}
    return g


def _split(objects: tuple[str, ...]) -> tuple[list[str], list[str]]:
    """The blocks and the bowls of a scene's objects."""
    return [o for o in objects if kind_of(o) == "block"], [o for o in objects if kind_of(o) == "bowl"]


def _memo(memo: dict, key: tuple, compute):
    got = memo.get(key, memo)  # the dict itself marks "not computed yet" (a verdict may be falsy)
    if got is memo:
        got = memo[key] = compute()
    return got


@dataclass(frozen=True)
class Each:
    """``quant`` of the blocks picked by ``sel:sp`` satisfy ``rel:rp``."""

    quant: str
    sel: str
    sp: str
    rel: str
    rp: str

    @property
    def key(self) -> str:
        return f"{self.quant} {self.sel}:{self.sp} {self.rel}:{self.rp}"

    @property
    def bits(self) -> float:
        return 1 + QUANT_BITS[self.quant] + self.selector_bits + NODES["relation"][self.rel].bits()

    @property
    def selector_bits(self) -> float:
        return NODES["selector"][self.sel].bits()

    @property
    def relation(self) -> Relation:
        return NODES["relation"][self.rel]  # type: ignore[return-value]

    def group(self, blocks, bowls) -> Group:
        sel = NODES["selector"][self.sel]
        skip = self.relation.refers(self.rp)
        return tuple(b for b in blocks if b != skip and sel.pick(b, tuple(bowls), self.sp))  # type: ignore[attr-defined]

    def group_f(self, f: Facts) -> Group:
        memo = _groups(f)
        got = memo.get(self.key)
        if got is None:
            got = memo[self.key] = self.group(f.blocks, f.bowls)
        return got

    def sentence(self) -> str:
        sel: Selector = NODES["selector"][self.sel]  # type: ignore[assignment]
        noun = sel.noun(self.sp)
        if self.relation.refers(self.rp) and self.sel == "all":
            noun = "other block"
        rel = self.relation.phrase(self.rp)
        if self.quant == "every":
            return f"every {noun} is {rel}"
        if self.quant == "none":
            return f"no {noun} is {rel}"
        n = NUMBER[self.quant[-1]]
        many = noun.replace("block", "blocks", 1) if n != "one" else noun
        verb = "is" if n == "one" else "are"
        return f"{'exactly' if self.quant.startswith('exactly') else 'at least'} {n} {many} {verb} {rel}"

    def vacuous(self, objects) -> bool:
        """Does the clause hold because the object its conditional relation names is absent?"""
        if not self.relation.vacuous_without_ref:
            return False
        r = self.relation.refers(self.rp)
        return r is not None and r not in objects

    def count(self, f: Facts) -> tuple[int, int]:
        """(blocks of the group satisfying the relation, group size); a relation naming an
        object that is not on the table holds for no block."""
        g = self.group_f(f)
        ref = self.relation.refers(self.rp)
        if ref is not None and ref not in f.pos:
            return 0, len(g)
        return sum(self.relation.ok(f, b, self.rp) for b in g), len(g)

    def holds(self, f: Facts) -> bool:
        return self.judge(f)[0]

    def score(self, f: Facts) -> float:
        return self.judge(f)[1]

    def judge(self, f: Facts) -> tuple[bool, float]:
        """(holds, score) from one count (the planner's hot path)."""
        if self.vacuous(f.pos):
            return True, 1.0
        cnt, size = self.count(f)
        return bool(quant_holds(self.quant, cnt, size)), quant_score(self.quant, cnt, size)

    def moved_off(self, fb: Facts, fa: Facts, b: str) -> bool:
        g = self.group_f(fa)
        if b not in g or self.vacuous(fa.pos):
            return False
        ref = self.relation.refers(self.rp)
        ok = (ref is None or ref in fa.pos) and self.relation.ok(fa, b, self.rp)
        if self.quant == "every":
            return not ok
        if self.quant == "none":
            return ok
        if self.quant.startswith("exactly"):
            return ok and self.count(fa)[0] > int(self.quant[-1])
        return False

    def possible(self, objects: tuple[str, ...], memo: dict | None = None) -> bool:
        """Static check in a scene of ``objects``; ``memo``: one dict per scene shared by many
        clauses (groups and per-block relation checks are computed once)."""
        memo = {} if memo is None else memo
        got = _memo(memo, ("each", self.sel, self.sp, self.rel, self.rp), lambda: self._can(objects, memo))
        if got is None:  # the relation's object is absent
            return self.relation.vacuous_without_ref
        size, can = got
        if not size:
            return False
        if self.quant == "every":
            return can == size
        if self.quant == "none":
            return True
        return can >= int(self.quant[-1])

    def _can(self, objects: tuple[str, ...], memo: dict) -> tuple[int, int] | None:
        """(group size, blocks of it that can satisfy the relation), None when the relation's
        object is absent; the same for every quantifier."""
        r = self.relation.refers(self.rp)
        if r is not None and r not in objects:
            return None
        g = _memo(memo, ("group", self.sel, self.sp, r), lambda: self.group(*_split(objects)))
        can = sum(_memo(memo, ("rel", self.rel, self.rp, b), lambda b=b: self.relation.possible(b, objects, self.rp))
                  for b in g)
        return len(g), can

    def suggest(self, state: WorldState, f: Facts) -> list[Skill]:
        if self.vacuous(f.pos):
            return []
        g = self.group_f(f)
        out: list[Skill] = []
        if self.quant == "none" or (self.quant.startswith("exactly") and self.count(f)[0] > int(self.quant[-1])):
            for b in g:
                if self.relation.ok(f, b, self.rp):
                    out += OnTable().targets(state, b, "")[:4] + [PutIn(block=b, bowl=w) for w in state.bowls]
            return out
        for b in g:
            if not self.relation.ok(f, b, self.rp):
                out += self.relation.targets(state, b, self.rp)
        return out


@dataclass(frozen=True)
class Form:
    """The blocks picked by ``sel:sp`` take the shape ``struct:stp``."""

    struct: str
    stp: str
    sel: str
    sp: str

    @property
    def key(self) -> str:
        return f"form {self.struct}:{self.stp} {self.sel}:{self.sp}"

    @property
    def bits(self) -> float:
        return 1 + NODES["structure"][self.struct].bits(self.stp) + self.selector_bits

    @property
    def selector_bits(self) -> float:
        return NODES["selector"][self.sel].bits()

    @property
    def structure(self) -> Structure:
        return NODES["structure"][self.struct]  # type: ignore[return-value]

    def group(self, blocks, bowls) -> Group:
        sel = NODES["selector"][self.sel]
        return tuple(b for b in blocks if sel.pick(b, tuple(bowls), self.sp))  # type: ignore[attr-defined]

    def group_f(self, f: Facts) -> Group:
        memo = _groups(f)
        k = ("form", self.sel, self.sp)
        got = memo.get(k)
        if got is None:
            got = memo[k] = self.group(f.blocks, f.bowls)
        return got

    def sentence(self) -> str:
        sel: Selector = NODES["selector"][self.sel]  # type: ignore[assignment]
        noun = sel.noun(self.sp).replace("block", "blocks", 1)
        return self.structure.sentence(f"the {noun}", self.stp)

    def judge(self, f: Facts) -> tuple[bool, float]:
        """(holds, score) in state ``f``, memoised per structure and group (clauses share them)."""
        return structure_judge(f, self.struct, self.stp, self.group_f(f))

    def holds(self, f: Facts) -> bool:
        return self.judge(f)[0]

    def score(self, f: Facts) -> float:
        return self.judge(f)[1]

    def moved_off(self, fb: Facts, fa: Facts, b: str) -> bool:
        g = self.group_f(fa)
        return b in g and not self.structure.moved_ok(fb, fa, g, b, self.stp)

    def possible(self, objects: tuple[str, ...], memo: dict | None = None) -> bool:
        memo = {} if memo is None else memo
        g = _memo(memo, ("group", self.sel, self.sp, None), lambda: self.group(*_split(objects)))
        return bool(g) and _memo(memo, ("structure", self.struct, self.stp, g),
                                 lambda: self.structure.possible(g, objects, self.stp))

    def suggest(self, state: WorldState, f: Facts) -> list[Skill]:
        return self.structure.suggest(state, self.group_f(f), self.stp)


Clause = Each | Form


def structure_judge(f: Facts, key: str, p: str, g: Group) -> tuple[bool, float]:
    """(holds, score) of structure ``key`` with parameter ``p`` over group ``g`` in ``f`` (an
    empty group holds with score 1), memoised on the state: every clause and compiled judge of
    the same (shape, group) reads one verdict."""
    k = ("form-judge", key, p, g)
    got = f.memo.get(k)
    if got is None:
        got = f.memo[k] = (True, 1.0) if not g else NODES["structure"][key].judge(f, g, p)  # type: ignore[attr-defined]
    return got


@dataclass(frozen=True)
class Goal:
    """One or two clauses; ``stays``: every block outside the clauses' groups keeps its place."""

    clauses: tuple[Clause, ...]
    stays: bool = False
    _bits: dict = field(default_factory=dict, compare=False, repr=False)  # per language version

    @property
    def key(self) -> str:
        return " & ".join(c.key for c in self.clauses) + (" & stays" if self.stays else "")

    @property
    def bits(self) -> float:
        """Description length L(z): how many clauses (geometric: n bits for n clauses), 1 bit for
        the stays flag, then the clauses. A clause after the first names its blocks by reference
        to the clause before — the same blocks, or the others (the complement) — for log2(3)
        bits instead of log2(3) + its selector's bits. The clauses' order says nothing, so
        P(z) sums over the orders in which z can be written (n! derivations)."""
        version = spoken()
        got = self._bits.get(version)
        if got is not None:
            return got
        n = len(self.clauses)
        if n == 1:
            bits = 2 + self.clauses[0].bits
        else:
            total = 0.0
            for order in permutations(self.clauses):
                b = order[0].bits
                for prev, c in zip(order, order[1:], strict=False):
                    b += c.bits - c.selector_bits + REUSE_BITS
                    if not _refers_back(prev, c):
                        b += c.selector_bits
                total += 2.0 ** -b
            bits = n + 1 - math.log2(total)
        self._bits[version] = bits
        return bits

    def sentence(self) -> str:
        parts = [c.sentence() for c in self.clauses]
        text = ", and ".join(parts)
        if self.stays:
            text += "; every other block stays where it is"
        return text[0].upper() + text[1:] + "."

    def groups(self, f: Facts) -> set[str]:
        return {b for c in self.clauses for b in c.group_f(f)}

    def holds(self, f: Facts) -> bool:
        return all(c.holds(f) for c in self.clauses)

    def score(self, f: Facts) -> float:
        return sum(c.score(f) for c in self.clauses) / len(self.clauses)

    def value(self, f: Facts) -> tuple[int, float]:
        """(clauses that hold, score): the planner's measure of progress, each clause judged once."""
        held, total = 0, 0
        for c in self.clauses:
            h, sc = c.judge(f)
            held += h
            total += sc
        return held, total / len(self.clauses)

    def moved_off(self, fb: Facts, fa: Facts, b: str) -> bool:
        if self.stays and b not in self.groups(fa):
            return True
        return any(c.moved_off(fb, fa, b) for c in self.clauses)

    def possible(self, objects: tuple[str, ...]) -> bool:
        return all(c.possible(tuple(objects)) for c in self.clauses)


def complement(sel: str, sp: str) -> tuple[str, str] | None:
    """The selector of the other blocks (every block has a colour, a class, a bowl or not)."""
    if sel == "colour":
        return "all-but", sp
    if sel == "all-but":
        return "colour", sp
    if sel == "class":
        return "class", "cool" if sp == "warm" else "warm"
    if sel == "matching":
        return "matching", "no" if sp == "yes" else "yes"
    if sel in ("colours", "all-but-colours"):
        return "all-but-colours" if sel == "colours" else "colours", sp
    return None


def _refers_back(prev: Clause, c: Clause) -> bool:
    """Are ``c``'s blocks those of ``prev`` or the others?"""
    return (c.sel, c.sp) == (prev.sel, prev.sp) or (c.sel, c.sp) == complement(prev.sel, prev.sp)


def parse_clause(key: str) -> Clause:
    """Inverse of ``Clause.key``."""
    parts = key.split(" ")
    if parts[0] == "form":
        struct, stp = parts[1].split(":", 1)
        sel, sp = parts[2].split(":", 1)
        return Form(struct, stp, sel, sp)
    sel, sp = parts[1].split(":", 1)
    rel, rp = " ".join(parts[2:]).split(":", 1)
    return Each(parts[0], sel, sp, rel, rp)


def parse_goal(key: str) -> Goal:
    """Inverse of ``Goal.key``."""
    items = key.split(" & ")
    stays = items[-1] == "stays"
    if stays:
        items = items[:-1]
    return Goal(tuple(parse_clause(k) for k in items), stays)


def all_clauses() -> list[Clause]:
    """Every clause of the language in force (each node type with each of its parameters)."""
    out: list[Clause] = []
    for sel, snode in nodes("selector").items():
        for sp in snode.params:
            for rel, rnode in nodes("relation").items():
                for rp in rnode.params:
                    for q in QUANTS:
                        out.append(Each(q, sel, sp, rel, rp))
            for st, stnode in nodes("structure").items():
                for stp in stnode.params:
                    out.append(Form(st, stp, sel, sp))
    return out
