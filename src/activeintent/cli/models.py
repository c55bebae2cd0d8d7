"""``activeintent model-bench``: how fast a model loads and answers (JSON on request)."""

from __future__ import annotations

import json
from typing import Annotated

import typer

from activeintent.llm.embedded import EmbeddedConfig
from activeintent.llm.registry import parse_spec
from activeintent.llm.speed import run_model_bench


def register(app: typer.Typer) -> None:
    @app.command("model-bench")
    def model_bench(
        model: Annotated[
            str, typer.Option("--model", help="embedded | gguf:/path/model.gguf | openai:<name>")
        ] = "embedded",
        base_url: Annotated[
            str | None, typer.Option("--base-url", help="OpenAI-compatible server URL")
        ] = None,
        repeats: Annotated[int, typer.Option(min=1, help="learner-sized calls to average")] = 3,
        threads: Annotated[
            int | None, typer.Option(min=1, help="embedded: CPU threads (default: all)")
        ] = None,
        n_ctx: Annotated[int, typer.Option(min=256, help="embedded: context tokens")] = 4096,
        as_json: Annotated[bool, typer.Option("--json", help="print one JSON object")] = False,
    ) -> None:
        """Load time, tokens/s (free text and structured), mean latency of a learner-sized call."""
        try:
            parse_spec(model)
        except ValueError as exc:
            raise typer.BadParameter(str(exc), param_hint="--model") from exc
        config = EmbeddedConfig(n_ctx=n_ctx)
        if threads is not None:
            config = config.model_copy(update={"n_threads": threads})
        result = run_model_bench(model, base_url=base_url, embedded=config, repeats=repeats)
        if as_json:
            typer.echo(json.dumps(result, indent=2))
            return
        from rich.console import Console
        from rich.table import Table

        table = Table(title=f"model-bench {result['model']}")
        table.add_column("measure")
        table.add_column("value", justify="right")
        table.add_row("load (s)", f"{result['load_s']:.2f}")
        table.add_row("free text tokens/s", f"{result['free_text']['tokens_per_s']:.1f}")
        table.add_row("structured tokens/s", f"{result['structured']['tokens_per_s']:.1f}")
        call = result["learner_call"]
        table.add_row(
            "learner-sized call, mean latency (s)",
            f"{call['latency_s_mean']:.2f} ({call['prompt_tokens_mean']:.0f} → "
            f"{call['completion_tokens_mean']:.0f} tokens)",
        )
        Console().print(table)

