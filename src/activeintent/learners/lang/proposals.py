"""New goals for the belief while it learns: neighbours of likely goals, and model proposals.

Both kinds enter the belief the same way (``Belief.extend``): with their own prior 2^-L(z) and
their likelihood on every answer so far, so the posterior is the one over the larger space —
nothing is accepted on a model's word.

- :func:`neighbours` — rejuvenation moves on expressions: change a clause's quantifier,
  selector (one colour of a set of colours at a time) or relation parameter, toggle "everything else stays", drop a clause, or join two
  likely goals into one conjunction (≤ ``MAX_CLAUSES`` clauses). Applied to the most probable
  goals after every answer, they reach goals the enumerated space left out (long conjunctions).
- :func:`propose_goals` — a language model reads the history h and the likely goals and
  writes new goals *in the language*, decoded under a JSON schema whose fields are enums of
  the language's words (llama.cpp turns it into a grammar), so every answer parses.

Proposals are de-duplicated by key; one that says the same as a goal already held (another
expression of the same behaviour) adds its own prior mass to that behaviour, as in a prior
over expressions.
"""

from __future__ import annotations

from itertools import product
from typing import Literal

from pydantic import BaseModel, Field, create_model

from activeintent.goals.goal import MAX_CLAUSES, QUANTS, Each, Form, Goal
from activeintent.goals.nodes import nodes
from activeintent.learners.prompts import render
from activeintent.llm.base import ChatModel, Message
from activeintent.world.colors import COLOR_NAMES


def _colours(param: str) -> frozenset[str]:
    """The colour names a selector's parameter says ("red", "blue+red")."""
    return frozenset(COLOR_NAMES).intersection(param.split("+"))


def _swap_params(c):
    """Clauses differing from ``c`` in one choice (quantifier, selector, relation/structure
    parameter). A selector of several named colours is one choice away only from a selector
    naming one of them: picking a set of colours is one choice per colour."""
    out = []
    near = _colours(c.sp)
    for sel, node in nodes("selector").items():
        for sp in node.params:
            named = _colours(sp)
            if len(named) > 1 and not named & near:
                continue
            if (sel, sp) != (c.sel, c.sp):
                out.append(Each(c.quant, sel, sp, c.rel, c.rp) if isinstance(c, Each) else Form(c.struct, c.stp, sel, sp))
    if isinstance(c, Each):
        out += [Each(q, c.sel, c.sp, c.rel, c.rp) for q in QUANTS if q != c.quant]
        out += [Each(c.quant, c.sel, c.sp, c.rel, rp) for rp in c.relation.params if rp != c.rp]
    else:
        out += [Form(c.struct, stp, c.sel, c.sp) for stp in c.structure.params if stp != c.stp]
    return out


def canonical(clauses, stays: bool) -> Goal | None:
    """The goal of ``clauses`` with its clauses in one order (by key), so one conjunction has one
    key; None when a clause repeats or there are more than ``MAX_CLAUSES``."""
    keys = [c.key for c in clauses]
    if not 1 <= len(keys) <= MAX_CLAUSES or len(set(keys)) != len(keys):
        return None
    return Goal(tuple(sorted(clauses, key=lambda c: c.key)), stays)


def neighbours(goals: list[Goal], partners: list[Goal] | None = None) -> list[Goal]:
    """Goals one move away from ``goals`` (the likely ones), and each of them joined with
    each of ``partners`` (more likely goals: a clause not yet tested may be the missing one)."""
    out: dict[str, Goal] = {}

    def add(g: Goal) -> None:
        got = canonical(g.clauses, g.stays)
        if got is not None:
            out.setdefault(got.key, got)

    for g in goals:
        add(Goal(g.clauses, not g.stays))
        for k, c in enumerate(g.clauses):
            rest = g.clauses[:k] + g.clauses[k + 1:]
            if rest:
                add(Goal(rest, g.stays))
            for new in _swap_params(c):
                add(Goal(rest + (new,), g.stays))
    for a, b in product(goals, partners or goals):
        if a.key != b.key:
            add(Goal(a.clauses + b.clauses, a.stays or b.stays))
    for g in goals:
        out.pop(g.key, None)
    return list(out.values())


# ---- model proposals -----------------------------------------------------------------------


def _words() -> tuple[list[str], list[str]]:
    """The selector words and predicate words of the language (relations and structures)."""
    selectors = [f"{k}:{p}" for k, n in nodes("selector").items() for p in n.params]
    predicates = [f"{k}:{p}" for k, n in nodes("relation").items() for p in n.params]
    predicates += [f"form {k}:{p}" for k, n in nodes("structure").items() for p in n.params]
    return selectors, predicates


def clause_schema() -> type[BaseModel]:
    """One clause as three enum fields (the node types registered now, plug-ins included)."""
    selectors, predicates = _words()
    return create_model(
        "ClauseProposal",
        quantifier=(Literal[tuple(QUANTS) + ("form",)], Field(description="'form' for a structure")),  # type: ignore[valid-type]
        blocks=(Literal[tuple(selectors)], ...),  # type: ignore[valid-type]
        predicate=(Literal[tuple(predicates)], ...),  # type: ignore[valid-type]
    )


def goals_schema(count: int) -> type[BaseModel]:
    clause = clause_schema()
    goal = create_model("GoalProposal", clauses=(list[clause], Field(min_length=1, max_length=MAX_CLAUSES)),  # type: ignore[valid-type]
                        others_stay=(bool, ...))
    return create_model("GoalProposals", goals=(list[goal], Field(min_length=1, max_length=count)))  # type: ignore[valid-type]


def to_goal(proposal) -> Goal | None:
    """A schema answer as a goal; None when its parts do not fit (a relation with "form", …)."""
    clauses = []
    for c in proposal.clauses:
        sel, sp = c.blocks.split(":", 1)
        if c.predicate.startswith("form "):
            if c.quantifier != "form":
                return None
            st, stp = c.predicate.removeprefix("form ").split(":", 1)
            clauses.append(Form(st, stp, sel, sp))
        else:
            if c.quantifier == "form":
                return None
            rel, rp = c.predicate.split(":", 1)
            clauses.append(Each(c.quantifier, sel, sp, rel, rp))
    return canonical(clauses, proposal.others_stay)


def propose_goals(llm: ChatModel, likely: list[tuple[Goal, float]], history: str, count: int = 3,
                  seed: int | None = None) -> tuple[list[Goal], int]:
    """Ask ``llm`` for up to ``count`` goals given h; returns (goals that fit, goals answered)."""
    prompt = render(
        "eq1_lang_goals",
        likely="\n".join(f"- {g.sentence()} (belief {w:.2f})\n  = {_as_fields(g)}" for g, w in likely),
        history=history or "(no answers yet)",
        count=count,
    )
    got = llm.structured([Message(role="user", content=prompt)], goals_schema(count), max_tokens=600,
                         prompt_version="eq1_lang_goals", seed=seed)
    goals = [g for g in (to_goal(p) for p in got.goals) if g is not None]  # type: ignore[attr-defined]
    return goals, len(got.goals)  # type: ignore[attr-defined]


def _as_fields(g: Goal) -> str:
    parts = []
    for c in g.clauses:
        if isinstance(c, Form):
            parts.append(f'{{"quantifier": "form", "blocks": "{c.sel}:{c.sp}", "predicate": "form {c.struct}:{c.stp}"}}')
        else:
            parts.append(f'{{"quantifier": "{c.quant}", "blocks": "{c.sel}:{c.sp}", "predicate": "{c.rel}:{c.rp}"}}')
    return f'{{"clauses": [{", ".join(parts)}], "others_stay": {str(g.stays).lower()}}}'
