"""The vocabulary of goals, shared by the learners that reason about goals and by the built-in
intentions (the library and the dev suite judge states with its nodes).

- facts.py — the relational facts of a world state (in a bowl, on a block, next to, regions, …);
- language.py — the goal language: selectors, relations and structures in a registry, clauses,
  goals z, their sentences and description length L(z), the language's versions;
- requested.py — the node types of language 2, those the corpus of requests needed;
- planner.py — one planner for every goal of the language, on the symbolic world model;
- planning.py — placing helpers (free grid points, areas) the planners share;
- recipes.py — a node of the language over a whole group with a fixed plan: the leaves of the
  bayes grammar (learners/bayes/hypotheses.py).

Held-out suites never import this package, not even through the modules they import
(intentions.placement, blockwise, base, lines): they are written with the world's helpers only,
so that whether the language can say them is measured, not true by construction.
"""

# Language 2's node types (requested.py builds on language.py) register whenever the package loads,
# so that no module sees the language without them.
import activeintent.goals.requested  # noqa: E402,F401
