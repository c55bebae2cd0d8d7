"""The `activeintent` command line. Each area registers its own commands (imports stay lazy)."""

from __future__ import annotations

import importlib

import typer

app = typer.Typer(
    name="activeintent",
    help="Large models as active learners of a user's intention from sparse signals.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)

# Each module defines register(app) and adds its commands.
_COMMAND_MODULES = (
    "activeintent.commands",
    "activeintent.act.commands",
    "activeintent.bench.commands",
    "activeintent.bench.perf",
    "activeintent.bench.verify",
    "activeintent.intentions.commands",
    "activeintent.learners.bayes.commands",
    "activeintent.llm.commands",
    "activeintent.sim.commands",
    "activeintent.web.commands",
)

for _module in _COMMAND_MODULES:
    importlib.import_module(_module).register(app)


if __name__ == "__main__":
    app()
