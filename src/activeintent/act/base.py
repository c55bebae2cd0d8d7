"""The executor interface: instruction y → plan (a list of skills), the first half of τ = f(y).

``plan`` and ``cap`` hand every y to their model (Code as Policies is called for every
instruction, as in the paper). With ``parser_first=True`` (the learners' ``structured``
variant, whose y is always in the canonical phrasing) they try the deterministic parser
(:mod:`activeintent.act.parse`) first and call the model only when y does not parse; without
a model they parse only. Whatever goes wrong is returned as a structured
:class:`ExecutionFailure` (never raised), which the learner receives as feedback. Every model
call is kept in ``transcript`` (instruction, the model's program or plan, the plan, the
failure) until :meth:`Executor.drain_transcript`, so round records can show it.
"""

from __future__ import annotations

import hashlib
import time
from abc import ABC, abstractmethod
from string import Template
from typing import Any

from activeintent.act.failures import ExecutionFailure, PlanResult, check_plan
from activeintent.act.parse import ParseError, parse_instruction
from activeintent.llm.backend import prompt_template
from activeintent.llm.base import ChatModel
from activeintent.world.skills import describe_plan
from activeintent.world.state import WorldState


def render_prompt(name: str, **values: object) -> tuple[str, str]:
    """(filled template ``name``, its version hash for the response cache)."""
    text = prompt_template(name)
    version = hashlib.sha256(text.encode()).hexdigest()[:12]
    return Template(text).substitute({k: str(v) for k, v in values.items()}).strip(), version


class Executor(ABC):
    """y → plan. Subclasses implement :meth:`_from_model` (one model call for y)."""

    name: str = "executor"

    def __init__(self, model: ChatModel | None = None, *, parser_first: bool = False) -> None:
        self.model = model
        self.parser_first = parser_first
        self.transcript: list[dict[str, Any]] = []

    def to_plan(self, instruction: str, state: WorldState) -> PlanResult:
        text = " ".join(str(instruction).split())  # free-form y may span lines
        if not text:
            return PlanResult(source=self.name, failure=ExecutionFailure(stage="parse", message="the instruction is empty"))
        if self.model is not None and not self.parser_first:
            result = self._model_plan(text, state)
        else:
            try:
                plan = parse_instruction(text, state.names)
            except ParseError as e:
                if e.kind != "syntax" or self.model is None:
                    return PlanResult(source="parse", failure=e.failure())
                result = self._model_plan(text, state)
            else:
                result = PlanResult(plan=plan, source="parse")
        if result.failure is None:
            result.failure = check_plan(result.plan, state)
        return result

    def _model_plan(self, instruction: str, state: WorldState) -> PlanResult:
        """One model call for y, kept in the transcript with what came of it."""
        start = time.perf_counter()
        result = self._from_model(instruction, state)
        failure = result.failure or (check_plan(result.plan, state) if result.plan else None)
        self.transcript.append({
            "template": f"executor_{self.name}",
            "model": getattr(self.model, "name", None),
            "instruction": instruction,
            "program": result.program,
            "plan": describe_plan(result.plan),
            "said": list(result.said),
            "failure": None if failure is None else f"{failure.stage}: {failure.message}",
            "s": round(time.perf_counter() - start, 4),
        })
        return result

    def drain_transcript(self) -> list[dict[str, Any]]:
        """The model calls since the last drain (for the round record)."""
        out, self.transcript = self.transcript, []
        return out

    @abstractmethod
    def _from_model(self, instruction: str, state: WorldState) -> PlanResult:
        """The plan for y from one model call (uses ``self.model``)."""
