"""A goal language: typed, compositional expressions over world states.

An expression (a *goal*) is one or two clauses, optionally with "every other block stays
where it is". A clause is either

- ``Each``: a quantifier, a selector of blocks and a per-block relation
  ("every warm-coloured block is in a bowl of its own colour", "no block is left of the red
  bowl", "exactly two blocks are in the blue bowl"), or
- ``Form``: a structure over the selected group ("the cool-coloured blocks form one tower,
  bottom to top in rainbow order").

Selectors, relations and structures are *node types* held in :data:`NODES`; adding one is a
single :func:`register` call (see ``examples/my_relation.py``). Every node type lists its
parameter choices; the description length of an expression is the sum over its nodes of
log2(number of choices at that node) — a uniform choice everywhere, nothing else — and the
prior of the learner is 2^-bits.

The language is versioned (:data:`LANGUAGES`): a node type carries the version that added it
(``since``), and what is enumerated or charged bits is the version in force (:func:`speaking`,
default :data:`LATEST`). A recorded episode names its version, so one run before the language
grew replays as it ran.

Selectors depend only on the scene (colours of the blocks and of the bowls present), never on
positions, so the group of a clause is fixed for a scene. A relation that names a block
("next to the red block") leaves that block out of the group.

Everything judges :class:`~activeintent.goals.facts.Facts` (relations of one state,
computed once and shared by all expressions).

The language lives in parts: nodes.py (node kinds, registry, versions), selectors.py,
relations.py, structures.py (the node types of language 1), requested.py (those of language
2) and goal.py (clauses, goals, parsing, enumeration). This module is its public face for
plug-ins and callers: what one needs to add a node type, speak a version and build, parse or
enumerate goals.
"""

from activeintent.goals.goal import (
    MAX_CLAUSES,
    QUANTS,
    Clause,
    Each,
    Form,
    Goal,
    all_clauses,
    parse_clause,
    parse_goal,
)
from activeintent.goals.nodes import (
    LANGUAGES,
    LATEST,
    NODES,
    Node,
    Relation,
    Selector,
    Structure,
    check_language,
    nodes,
    register,
    speaking,
    spoken,
)

__all__ = [
    "LANGUAGES", "LATEST", "MAX_CLAUSES", "NODES", "QUANTS", "Clause", "Each", "Form", "Goal", "Node",
    "Relation", "Selector", "Structure", "all_clauses", "check_language", "nodes", "parse_clause",
    "parse_goal", "register", "speaking", "spoken",
]
