"""The vocabulary of goals, shared by the learners that reason about goals and by the built-in
intentions (the library and the dev suite judge states with its nodes).

- facts.py — the relational facts of a world state (in a bowl, on a block, next to, regions, …);
- language.py — the goal language's public face (what plug-ins and callers import); its parts:
  - nodes.py — node kinds, the registry of node types, the language's versions;
  - selectors.py, relations.py, structures.py — the node types of language 1;
  - requested.py — the node types of language 2, those the corpus of requests needed;
  - goal.py — clauses, goals z, their sentences and description length L(z), parsing;
- prior.py — priors over goals fitted to the corpus of requests;
- planner.py — one planner for every goal of the language, on the symbolic world model;
- planning.py — placing helpers (free grid points, areas) the planners share;
- recipes.py — a node of the language over a whole group with a fixed plan: the leaves of the
  bayes grammar (learners/bayes/hypotheses.py).

Held-out suites never import this package, not even through the modules they import
(intentions.placement, blockwise, base, lines): they are written with the world's helpers only,
so that whether the language can say them is measured, not true by construction.
"""

# Every node type registers whenever the package loads, so that no module sees the language
# without some of them. Registration order is enumeration order (the lang learners' hypothesis
# space, committed results): selectors, relations, structures, then language 2's (requested.py).
import activeintent.goals.selectors  # noqa: E402,F401,I001
import activeintent.goals.relations  # noqa: E402,F401
import activeintent.goals.structures  # noqa: E402,F401
import activeintent.goals.requested  # noqa: E402,F401
