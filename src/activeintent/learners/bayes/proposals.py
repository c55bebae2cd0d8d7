"""Open-ended hypotheses: a language model proposes new z in words plus a predicate in code.

When the belief collapses (no hypothesis of the grammar explains the signals) or a model is
given, the model writes new candidate intentions: a sentence and the body of a Python
predicate ``holds(world)`` over a plain-data view of the relations. The code is untrusted: it
runs only in the act sandbox (act/sandbox.py: AST allow-list, separate process, limits), in
batches — one sandbox call judges every state a query needs.
"""

from __future__ import annotations

import re
import textwrap
from typing import Protocol

import numpy as np
from pydantic import BaseModel, Field, field_validator

from activeintent.act.guard import MAX_PROGRAM_CHARS
from activeintent.act.sandbox import default_sandbox
from activeintent.goals.facts import Facts, facts
from activeintent.learners.bayes.hypotheses import Hypothesis, random_scene
from activeintent.learners.prompts import render
from activeintent.llm.base import ChatModel, Message
from activeintent.world import WorldState, layout
from activeintent.world.colors import WARM_COLORS
from activeintent.world.scene import color_of


class ProposedIntention(BaseModel):
    description: str = Field(min_length=3, max_length=300)
    predicate: str = Field(min_length=1, max_length=3000, description="body of def holds(world)")

    @field_validator("description")
    @classmethod
    def _words(cls, text: str) -> str:
        # A small base model sometimes answers "..." or a bare symbol: that is no intention.
        if len(re.findall(r"[A-Za-z]{2,}", text)) < 3:
            raise ValueError("a proposed intention must be a sentence of at least three words")
        return text


class Proposals(BaseModel):
    hypotheses: list[ProposedIntention] = Field(default_factory=list, max_length=5)


class PredicateRunner(Protocol):
    """Runs a predicate body over many worlds; returns one bool per world, or raises."""

    def __call__(self, body: str, worlds: list[dict]) -> list[bool]: ...


def world_view(f: Facts) -> dict:
    """The plain-data view of a state that proposed predicates read."""
    names = list(f.blocks) + list(f.bowls)
    return {
        "blocks": list(f.blocks),
        "bowls": list(f.bowls),
        "color": {n: color_of(n) for n in names},
        "warm": sorted(WARM_COLORS),
        "in_bowl": dict(f.bowl_of),
        "on": dict(f.below),
        "next_to": [sorted(p) for p in f.near],
        "position": {n: [round(f.xy[n][0], 4), round(f.xy[n][1], 4)] for n in names},
        "table_position": dict(f.cell),
    }


def batch_program(body: str, worlds: list[dict]) -> str:
    """A sandbox program that judges every world and says the answers as one string."""
    return "\n".join(
        [
            f"WORLDS = {worlds!r}",
            "def holds(world):",
            textwrap.indent(textwrap.dedent(body).strip() or "return False", "    "),
            "answers = []",
            "for world in WORLDS:",
            "    try:",
            "        answers.append('1' if holds(world) else '0')",
            "    except:",
            "        answers.append('0')",
            "say(''.join(answers))",
        ]
    )


def batch_programs(body: str, worlds: list[dict], limit: int | None = None) -> list[tuple[str, list[dict]]]:
    """``batch_program`` over consecutive groups of ``worlds``, each program within the sandbox's
    size limit (so that many worlds make several programs, never one that is refused)."""
    limit = limit or MAX_PROGRAM_CHARS
    base = len(batch_program(body, []))
    groups: list[list[dict]] = []
    size = base
    for world in worlds:
        extra = len(repr(world)) + 2
        if base + extra > limit:
            raise ValueError(f"one world alone makes a predicate program over {limit} characters")
        if not groups or size + extra > limit:
            groups.append([])
            size = base
        groups[-1].append(world)
        size += extra
    return [(batch_program(body, group), group) for group in groups]


class SandboxRunner:
    """Runs predicate batches in the act sandbox (one child process per batch, several batches
    when the worlds do not fit in one program)."""

    def __init__(self, sandbox=None):
        self._sandbox = sandbox

    def __call__(self, body: str, worlds: list[dict]) -> list[bool]:
        sandbox = self._sandbox or default_sandbox()
        out = ""
        for program, group in batch_programs(body, worlds):
            probe = WorldState(positions={n: (p[0], p[1], 0.02) for n, p in group[0]["position"].items()})
            result = sandbox.run(program, probe)
            if result.error or not result.said:
                raise ValueError(result.error or "the predicate said nothing")
            part = result.said[-1].strip()
            if len(part) != len(group) or set(part) - {"0", "1"}:
                raise ValueError(f"malformed predicate output {part[:40]!r}")
            out += part
        return [c == "1" for c in out]


class ProposedHypothesis(Hypothesis):
    """A model-proposed z: no planner and no graded score; judged by its sandboxed predicate."""

    def __init__(self, description: str, body: str, runner: PredicateRunner, bits: float = 0.0):
        self.clauses = ()
        self.bits = bits
        self.body = body
        self.runner = runner
        self.description = description
        self.name = "proposed:" + " ".join(description.lower().split())[:60]

    def prefetch(self, states: list[Facts]) -> None:
        key = ("proposed", self.name)
        todo = [f for f in dict.fromkeys(states) if key not in f.memo]
        if not todo:
            return
        try:
            answers = self.runner(self.body, [world_view(f) for f in todo])
        except Exception:  # a crashing predicate holds nowhere (and was screened at proposal)
            answers = [False] * len(todo)
        for f, a in zip(todo, answers, strict=True):
            f.memo[key] = a

    def holds_f(self, f: Facts) -> bool:
        key = ("proposed", self.name)
        if key not in f.memo:
            self.prefetch([f])
        return bool(f.memo[key])

    def score_f(self, f: Facts) -> float:
        return float(self.holds_f(f))

    def moved_off(self, fb: Facts, fa: Facts, block: str) -> bool:
        return False

    def feasible(self, scene) -> bool:
        return True

    def plans(self, state: WorldState, variants: int | None = None) -> list:
        return []


def compile_proposal(p: ProposedIntention, runner: PredicateRunner, probes: list[Facts]) -> ProposedHypothesis | None:
    """A hypothesis from a proposal, or None when its code is refused or crashes on probes."""
    h = ProposedHypothesis(p.description.strip(), p.predicate, runner)
    if probes:
        try:
            runner(p.predicate, [world_view(f) for f in probes])
        except Exception:
            return None
    return h


def _summarise(observations) -> str:
    lines = []
    for i, obs in enumerate(observations, 1):
        shown = "; ".join(obs.texts) if getattr(obs, "texts", None) else "(not recorded)"
        lines.append(f"{i}. scene {obs.scene}: outcome(s): {shown}. Answer: {obs.answer.describe()}.")
    return "\n".join(lines) or "(none yet)"


def propose_hypotheses(
    llm: ChatModel,
    top: list[tuple[Hypothesis, float]],
    observations: list,
    count: int = 3,
    runner: PredicateRunner | None = None,
) -> list[Hypothesis]:
    """Ask ``llm`` for new z; keep those whose predicate compiles and runs in the sandbox."""
    prompt = render(
        "eq1_bayes_hypotheses",
        candidates="\n".join(f"- {h.description} (belief {w:.2f})" for h, w in top),
        observations=_summarise(observations),
        count=count,
    )
    # A ModelError propagates: the learner records it (a proposal that never came is not "0 calls").
    got = llm.structured([Message(role="user", content=prompt)], Proposals, max_tokens=700)
    runner = runner or SandboxRunner()
    probes = [f for obs in observations for f in obs.finals][:6]
    if not probes:
        rng = np.random.default_rng(0)

        probes = [facts(WorldState(positions=layout(random_scene(rng), 0)))]
    out = []
    for p in got.hypotheses[:count]:
        h = compile_proposal(p, runner, probes)
        if h is not None:
            out.append(h)
    return out
