"""The `activeintent` command line: one module per command group, each with ``register(app)``;
the library below never defines a command."""

from __future__ import annotations

import functools
import importlib
import sys

import typer

from activeintent.cli.options import check_only
from activeintent.registry import load_plugin

app = typer.Typer(
    name="activeintent",
    help="Large models as active learners of a user's intention from sparse signals.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)

# Each module defines register(app) and adds its commands.
_COMMAND_MODULES = (
    "activeintent.cli.run",
    "activeintent.cli.bench",
    "activeintent.cli.verify",
    "activeintent.cli.perf_bench",
    "activeintent.cli.serve",
    "activeintent.cli.web_bench",
    "activeintent.cli.methods",
    "activeintent.cli.intentions",
    "activeintent.cli.hypotheses",
    "activeintent.cli.prior",
    "activeintent.cli.models",
    "activeintent.cli.act_bench",
    "activeintent.cli.sim",
)

for _module in _COMMAND_MODULES:
    importlib.import_module(_module).register(app)

# Commands that only measure or demonstrate: in check-only mode their options are parsed and
# nothing runs (run, bench and serve validate deeper themselves).
_MEASURING = {"coverage", "sim-demo", "sim-bench", "model-bench", "act-bench", "bayes-bench", "perf-bench", "bench-verify"}


def _checked(callback):
    @functools.wraps(callback)
    def wrapper(*args, **kwargs):
        if check_only():
            return None
        return callback(*args, **kwargs)

    return wrapper


for _info in app.registered_commands:
    if (_info.name or "") in _MEASURING:
        _info.callback = _checked(_info.callback)



def main(argv: list[str] | None = None) -> None:
    """The `activeintent` program: plug-in files named with ``--plugin`` load before the command
    line is built, so their learners' settings are options too (and shown by ``--help``)."""
    args = list(sys.argv[1:] if argv is None else argv)
    for i, arg in enumerate(args):
        path = args[i + 1] if arg == "--plugin" and i + 1 < len(args) else arg.removeprefix("--plugin=")
        if path != arg or arg == "--plugin":
            try:
                load_plugin(path)
            except (OSError, ValueError, SyntaxError):
                pass  # the command reports it, naming the option
    app(args=args, prog_name="activeintent")
