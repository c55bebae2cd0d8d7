"""`activeintent act-bench`: executor overhead excluding the model call."""

from __future__ import annotations

import typer

from activeintent.act.isolation import SandboxUnavailable
from activeintent.act.overhead import run_bench


def register(app: typer.Typer) -> None:
    @app.command("act-bench")
    def act_bench(
        json_out: bool = typer.Option(False, "--json", help="Print the figures as JSON."),
        programs: int = typer.Option(20, min=1, max=1000, help="Programs/instructions per executor."),
        seed: int = typer.Option(0, help="Seed for the scenes."),
    ) -> None:
        """Executor overhead without the model call: parsing, plan validation, sandbox cost."""
        import json

        try:
            report = run_bench(programs, seed)
        except SandboxUnavailable as e:  # no bubblewrap and no --unsafe-no-isolation consent
            typer.echo(f"act-bench: {e}", err=True)
            raise typer.Exit(2) from None
        if json_out:
            typer.echo(json.dumps(report, indent=2))
            return
        from rich.console import Console
        from rich.table import Table

        table = Table(title=f"Executor overhead (mean of {programs}, model call excluded)")
        table.add_column("stage")
        table.add_column("mean ms", justify="right")
        table.add_column("max ms", justify="right")
        for key, value in report.items():
            if isinstance(value, dict):
                table.add_row(key, f"{value['mean_s'] * 1e3:.2f}", f"{value['max_s'] * 1e3:.2f}")
        Console().print(table)
        Console().print(
            f"sandbox start-up {report['sandbox_startup_s']:.3f} s; overhead target "
            f"< 0.2 s per program: {'met' if report['meets_target'] else 'NOT met'}"
        )
