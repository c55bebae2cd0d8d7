"""Executors by ``--executor`` name (a registry: add your own with ``EXECUTORS.register`` in a
``--plugin`` file): ``parse`` reads the canonical phrasing only; ``plan`` and ``cap`` call their
model for every y (``cap``: Code as Policies in the sandbox)."""

from __future__ import annotations

from typing import Any

from activeintent.act.base import Executor
from activeintent.act.cap import CapExecutor
from activeintent.act.failures import PlanResult
from activeintent.act.plan import PlanExecutor
from activeintent.llm.base import ChatModel
from activeintent.registry import Registry
from activeintent.world.state import WorldState

EXECUTORS: Registry[Executor] = Registry("executor")


class ParseExecutor(Executor):
    """``--executor parse``: the canonical phrasing only, no model."""

    name = "parse"

    def _from_model(self, instruction: str, state: WorldState) -> PlanResult:  # pragma: no cover
        raise AssertionError("the parse executor has no model")


@EXECUTORS.register("parse", help="the canonical phrasing only, no model")
def _parse(model: ChatModel | None = None, *, parser_first: bool = False, **options: Any) -> Executor:
    return ParseExecutor(model=None)


@EXECUTORS.register("plan", help="the model writes the plan as JSON skills")
def _plan(model: ChatModel | None = None, *, parser_first: bool = False, **options: Any) -> Executor:
    return PlanExecutor(model, parser_first=parser_first, **options)


@EXECUTORS.register("cap", help="Code as Policies: the model writes a program, run in the sandbox")
def _cap(model: ChatModel | None = None, *, parser_first: bool = False, **options: Any) -> Executor:
    return CapExecutor(model, parser_first=parser_first, **options)


def make_executor(name: str, model: ChatModel | None = None, *, parser_first: bool = False, **options: Any) -> Executor:
    """The executor for ``--executor NAME``.

    ``plan`` and ``cap`` call their model for every y; ``parser_first=True`` (the structured
    variant) lets canonical y skip the model. Without a model, ``plan`` and ``cap`` read only
    the canonical phrasing (like ``parse``) and report anything else as a parse failure;
    methods that plan by themselves need no model.
    """
    return EXECUTORS.make(name.strip().lower(), model, parser_first=parser_first, **options)
