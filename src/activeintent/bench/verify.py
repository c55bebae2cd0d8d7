"""`activeintent bench-verify DIR`: re-run a sample of a results folder's episodes from its
recorded settings (``bench.json``) and compare them with the recorded lines, so published
numbers cannot drift from the code silently."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

# What must come out the same (timings, token counts and tracebacks may differ).
COMPARED = ("success", "success_at", "signals_used", "answers", "test_excluded", "final_z", "final_goal")


def register(app: typer.Typer) -> None:
    app.command(name="bench-verify")(bench_verify)


def verify(folder: Path, sample: int, methods: list[str] | None = None) -> list[dict]:
    """Differences between recorded and re-run episodes (empty when they agree)."""
    from activeintent.bench.runner import BenchOptions, run_item
    from activeintent.records import read_results

    options = BenchOptions.model_validate_json((folder / "bench.json").read_text())
    records = [r for r in read_results(folder / "results.jsonl") if not r.get("error")]
    if methods:
        records = [r for r in records if r["method"] in methods]
    # A deterministic spread: the records of the lowest trials, across methods and intentions.
    records.sort(key=lambda r: (r["trial"], r["intention"], r["method"]))
    diffs = []
    for rec in records[:sample]:
        from activeintent.bench.runner import WorkItem

        item = WorkItem(method=rec["method"], intention=rec["intention"], trial=rec["trial"])
        again = run_item(item, options.run, options.seed, str(folder), keep=False)
        changed = {k: (rec.get(k), again.get(k)) for k in COMPARED if rec.get(k) != again.get(k)}
        if changed:
            diffs.append({"method": item.method, "intention": item.intention, "trial": item.trial, "changed": changed})
    return diffs


def bench_verify(
    folder: Annotated[Path, typer.Argument(help="A results folder written by `bench`")],
    sample: Annotated[int, typer.Option(min=1, help="Episodes to re-run")] = 4,
    methods: Annotated[str, typer.Option(help="Only these methods (comma-separated)")] = "",
) -> None:
    """Re-run a sample of a results folder and compare; exit 1 when the code no longer gives
    the recorded results."""
    if not (folder / "bench.json").is_file():
        typer.echo(f"error: {folder} has no bench.json (not a results folder written by `bench`)", err=True)
        raise typer.Exit(2)
    diffs = verify(folder, sample, [m for m in methods.split(",") if m] or None)
    if diffs:
        typer.echo(json.dumps(diffs, indent=2, default=str))
        typer.echo(f"{len(diffs)} of {sample} re-run episodes differ from {folder}/results.jsonl", err=True)
        raise typer.Exit(1)
    typer.echo(f"{sample} re-run episodes agree with {folder}/results.jsonl")
