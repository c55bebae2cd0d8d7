"""`activeintent intentions`: the built-in hidden intentions, and how to add your own."""

from __future__ import annotations

from typing import Annotated

import typer

from activeintent.intentions.registry import (
    PAPER_INTENTIONS,
    IntentionError,
    all_intentions,
    load_intention_file,
)


def register(app: typer.Typer) -> None:
    app.command(name="intentions")(intentions)


def intentions(
    intention_file: Annotated[
        str | None,
        typer.Option("--intention-file", help="Also check and show your own intention: path.py:NAME"),
    ] = None,
) -> None:
    """List the intentions a simulated user can hold (name, one sentence, from the paper or not)."""
    from rich.console import Console
    from rich.table import Table

    console = Console()
    rows = [(i.name, i.description, "paper" if i.name in PAPER_INTENTIONS else "") for i in all_intentions()]
    if intention_file:
        try:
            own = load_intention_file(intention_file)
        except IntentionError as err:
            console.print(f"[red]error:[/red] {err}")
            raise typer.Exit(2) from None
        rows.append((own.name, own.description, f"yours ({intention_file})"))
    table = Table(title="Intentions (use with --intention NAME)")
    table.add_column("name", style="bold cyan", no_wrap=True)
    table.add_column("what the user wants")
    table.add_column("source")
    for row in rows:
        table.add_row(*row)
    console.print(table)
    console.print(
        "Add your own: write an Intention subclass in a Python file and pass "
        "[bold]--intention-file path.py:NAME[/bold] wherever --intention is accepted "
        "(example: examples/my_intention.py, guide: docs/intentions.md)."
    )
