"""The goal language's node types and their registry: the three kinds (selector, relation,
structure), :data:`NODES`, :func:`register`, and the language's versions (:data:`LANGUAGES`,
:func:`speaking`) that say which registered node types are in force.

Registration order is enumeration order (and so the order of the lang learners' hypothesis
space): goals/__init__.py imports the modules that register, in their order.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from activeintent.goals.facts import Facts
from activeintent.memo import BoundedCache
from activeintent.registry import Registry
from activeintent.world import Skill, WorldState

Group = tuple[str, ...]


class Node:
    """A node type of the grammar: a key, a kind and its parameter choices."""

    kind: str = ""
    key: str = ""
    params: tuple[str, ...] = ("",)
    since: int = 1  # the language version that added this node type

    def bits(self, p: str | None = None) -> float:
        """log2 of the choices below the kind: which type of node, then which parameter (in the
        language in force; memoised: every enumeration asks it for every clause)."""
        key = (self.kind, self.key, p, spoken())
        got = _NODE_BITS.get(key)
        if got is None:
            got = _NODE_BITS.put(key, math.log2(len(nodes(self.kind))) + self.param_bits(p))
        return got

    def param_bits(self, p: str | None) -> float:
        """Bits of parameter ``p``: a uniform choice unless the node's parameters are a grammar."""
        return math.log2(len(self.params))


class Selector(Node):
    """Which blocks a clause is about. ``pick`` sees a block and the scene's bowls only."""

    kind = "selector"

    def noun(self, p: str) -> str:  # singular, e.g. "warm-coloured block"
        raise NotImplementedError

    def pick(self, block: str, bowls: tuple[str, ...], p: str) -> bool:
        raise NotImplementedError


class Relation(Node):
    """A property of one block in a state."""

    kind = "relation"
    # True: with the object it names off the table, a clause of it holds whatever its quantifier
    # (a request's "if there is one"); False: it holds for no block then.
    vacuous_without_ref = False

    def phrase(self, p: str) -> str:  # after "is", e.g. "in a bowl of its own colour"
        raise NotImplementedError

    def ok(self, f: Facts, b: str, p: str) -> bool:
        raise NotImplementedError

    def refers(self, p: str) -> str | None:
        """The object the relation names (it must be in the scene; a named block is not in the group)."""
        return None

    def same_ok(self, p: str) -> tuple[str, str]:
        """The relation and parameter whose ``ok`` this one's is (itself, unless it wraps another):
        a judge computes each such verdict once per state."""
        return self.key, p

    def possible(self, b: str, objects: tuple[str, ...], p: str) -> bool:
        """Static check: can ``b`` be made to satisfy the relation in a scene of ``objects``?"""
        r = self.refers(p)
        return r is None or (r in objects and r != b)

    def targets(self, state: WorldState, b: str, p: str) -> list[Skill]:
        """Suggested skills that may make ``b`` satisfy the relation (the planner tries them first)."""
        return []


class Structure(Node):
    """A shape the whole group takes."""

    kind = "structure"
    min_size = 2

    def __init__(self, min_size: int | None = None):
        """``min_size``: the smallest group that can take the shape, when not the type's own
        (a lone block is a tower / row / cluster of one in the bayes grammar's leaves)."""
        if min_size is not None:
            self.min_size = min_size

    def sentence(self, subject: str, p: str) -> str:  # subject: "the warm-coloured blocks"
        raise NotImplementedError

    def holds(self, f: Facts, g: Group, p: str) -> bool:
        raise NotImplementedError

    def score(self, f: Facts, g: Group, p: str) -> float:
        return float(self.holds(f, g, p))

    def judge(self, f: Facts, g: Group, p: str) -> tuple[bool, float]:
        """(holds, score) of a non-empty group (one call, so that a structure can share work)."""
        return self.holds(f, g, p), float(self.score(f, g, p))

    def moved_ok(self, fb: Facts, fa: Facts, g: Group, b: str, p: str) -> bool:
        return True

    def possible(self, g: Group, objects: tuple[str, ...], p: str) -> bool:
        return len(g) >= self.min_size

    def suggest(self, state: WorldState, g: Group, p: str) -> list[Skill]:
        return []


# The node types by kind, each kind a registry (plug-ins add theirs with :func:`register`).
NODES: dict[str, Registry[Node]] = {kind: Registry(kind) for kind in ("selector", "relation", "structure")}

# The language's versions: what each added (data/requests/README.md tells how it grew).
LANGUAGES = {
    1: "the language of the corpus's first translation pass (commit 08fb5f6)",
    2: "grown by the corpus rule: constructs that at least 3 untranslatable requests need",
}
LATEST = max(LANGUAGES)
_SPOKEN: ContextVar[int] = ContextVar("language", default=LATEST)


def check_language(version: int) -> int:
    if version not in LANGUAGES:
        raise ValueError(f"unknown language version {version!r}; valid: {', '.join(map(str, LANGUAGES))}")
    return version


def spoken() -> int:
    """The language version in force (:func:`speaking`)."""
    return _SPOKEN.get()


@contextmanager
def speaking(version: int) -> Iterator[int]:
    """Enumerate and charge bits in language ``version`` inside the block."""
    token = _SPOKEN.set(check_language(version))
    try:
        yield version
    finally:
        _SPOKEN.reset(token)


# The node types in force by (kind, version), and a node's bits by (kind, key, parameter,
# version): functions of what is registered, so register() empties both. Sizes hold every
# entry of every version (some 1,300 bits).
_IN_FORCE: BoundedCache[tuple[str, int], dict[str, Node]] = BoundedCache(64)
_NODE_BITS: BoundedCache[tuple, float] = BoundedCache(1 << 16)


def nodes(kind: str, version: int | None = None) -> dict[str, Node]:
    """The node types of ``kind`` in language ``version`` (default: the one in force), in
    registration order."""
    v = spoken() if version is None else version
    got = _IN_FORCE.get((kind, v))
    if got is None:
        got = _IN_FORCE.put((kind, v), {k: n for k, n in NODES[kind].items() if n.since <= v})
    return got


def register(node: Node) -> Node:
    """Add a node type to the language (selector, relation or structure); a plug-in's node
    joins every version (set ``since`` to keep it out of the older ones)."""
    if node.kind not in NODES:
        raise ValueError(f"unknown node kind {node.kind!r}; valid: {', '.join(NODES)}")
    if not node.key or " " in node.key or "|" in node.key:
        raise ValueError(f"a node key is one word without '|', got {node.key!r}")
    NODES[node.kind].register(node.key, node)
    _IN_FORCE.clear()
    _NODE_BITS.clear()
    return node
