"""`activeintent methods`: the learners by their command-line name."""

from __future__ import annotations

import typer

from activeintent.learners.registry import get_method, method_names


def register(app: typer.Typer) -> None:
    app.command(name="methods")(methods)


def methods() -> None:
    """List the methods (learners) with their signal and whether they need a model."""
    from rich.console import Console
    from rich.table import Table

    table = Table(title="methods")
    for col in ("method", "family", "signal", "needs a model", "what it does"):
        table.add_column(col, overflow="fold")
    for name in method_names():
        m = get_method(name)
        table.add_row(name, m.family, m.signal, "yes" if m.needs_llm else "no", m.help)
    Console().print(table)
