"""`activeintent bench-verify DIR`: re-run a sample of a results folder's episodes and compare
them with its records (the checks themselves: bench/verify.py)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from activeintent.bench.verify import StaleFolder, committed_folders, methods_of, untrusted, verify


def register(app: typer.Typer) -> None:
    app.command(name="bench-verify")(bench_verify)


def _short(value) -> str:
    text = json.dumps(value, default=str)
    return text if len(text) <= 90 else text[:87] + "..."


def _report(folder: Path, diffs: list[dict], sample: int) -> bool:
    for d in diffs:
        typer.echo(f"{d['method']} · {d['intention']} · trial {d['trial']}:")
        for key, (recorded, again) in d["changed"].items():
            typer.echo(f"  {key}\n    recorded: {_short(recorded)}\n    re-run:   {_short(again)}")
    if diffs:
        typer.echo(f"{len(diffs)} of {sample} re-run episodes differ from {folder}/results.jsonl", err=True)
        return False
    typer.echo(f"{sample} re-run episodes agree with {folder}/results.jsonl")
    return True


def bench_verify(
    folder: Annotated[Path | None, typer.Argument(help="A results folder written by `bench`")] = None,
    sample: Annotated[int, typer.Option(min=1, help="Episodes to re-run (spread over the methods)")] = 4,
    methods: Annotated[str, typer.Option(help="Only these methods (comma-separated)")] = "",
    every: Annotated[bool, typer.Option("--all", help="Every committed folder (docs/results/*, experiments/*/results/*), "
                                        "one episode of every method each (run from the repository's root)")] = False,
) -> None:
    """Check every record of a results folder against its bench.json and itself, re-run a
    sample and compare; exit 1 when a record does not belong to the folder or the code no
    longer gives the recorded results, 2 when the folder cannot be verified."""
    if every:
        folders = committed_folders(Path.cwd())
        if not folders:
            typer.echo("error: no committed results folders here (run from the repository's root)", err=True)
            raise typer.Exit(2)
        bad, stale = [], []
        for i, f in enumerate(folders, 1):
            typer.echo(f"[{i}/{len(folders)}] {f}")
            n = len(methods_of(f))
            foreign = untrusted(f)
            for r in foreign:
                typer.echo(f"  results.jsonl line {r.line} not trusted ({r.kind}): {r.reason}")
            try:
                ok = _report(f, verify(f, n), n) and not foreign
            except StaleFolder as err:
                typer.echo(f"  cannot be verified: {err}")
                stale.append(f)
                continue
            if not ok:
                bad.append(f)
        typer.echo(f"{len(folders) - len(bad) - len(stale)} folders agree, {len(bad)} differ, "
                   f"{len(stale)} cannot be verified")
        raise typer.Exit(1 if bad else 0)
    if folder is None:
        typer.echo("error: give a results folder, or --all", err=True)
        raise typer.Exit(2)
    if not (folder / "bench.json").is_file():
        typer.echo(f"error: {folder} has no bench.json (not a results folder written by `bench`)", err=True)
        raise typer.Exit(2)
    bad = untrusted(folder)
    for r in bad:
        typer.echo(f"results.jsonl line {r.line} not trusted ({r.kind}): {r.reason}")
    if bad:
        typer.echo(f"{len(bad)} line(s) of {folder}/results.jsonl do not belong to the folder", err=True)
        raise typer.Exit(1)
    try:
        diffs = verify(folder, sample, [m for m in methods.split(",") if m] or None)
    except StaleFolder as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from None
    if not _report(folder, diffs, sample):
        raise typer.Exit(1)
    typer.echo(f"every record of {folder}/results.jsonl is consistent with its bench.json")
