"""`activeintent bench`: every method × intention × trial, resumable, with a report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from activeintent import options as opt


def register(app: typer.Typer) -> None:
    app.command(name="bench")(bench)


def _split(text: str) -> list[str]:
    return [t.strip() for t in text.split(",") if t.strip()]


def bench(
    methods: Annotated[str, typer.Option("--methods", help="Comma-separated methods (default: all)")] = "",
    intentions: Annotated[str, typer.Option("--intentions", help="Comma-separated intentions")] = "align,stack,color-match,color-mismatch",
    intention_file: Annotated[list[str] | None, typer.Option("--intention-file", help="Add your own: path.py:NAME (repeatable)")] = None,
    trials: Annotated[int, typer.Option("--trials", min=1)] = 5,
    rounds: opt.Rounds = 5,
    seed: opt.Seed = 0,
    llm: opt.Llm = "embedded",
    vlm: opt.Vlm = None,
    base_url: opt.BaseUrl = None,
    cache: opt.Cache = None,
    cache_mode: opt.CacheMode = "record",
    executor: opt.Executor = "plan",
    retriever: opt.Retriever = "symbolic",
    user_beta: opt.UserBeta = float("inf"),
    reaction_delay: opt.ReactionDelay = "0.5,0.15",
    false_stop: opt.FalseStop = 0.0,
    missed_stop: opt.MissedStop = 0.0,
    jobs: Annotated[int, typer.Option("--jobs", min=1, help="Episodes run in parallel (processes)")] = 1,
    videos: Annotated[bool, typer.Option(help="Save a GIF per executed trajectory")] = False,
    retry_errors: Annotated[bool, typer.Option(help="Re-run episodes that ended in an error")] = False,
    out: Annotated[Path, typer.Option("--out", help="Results folder; re-running with it resumes")] = Path("runs/bench"),
) -> None:
    """Compare methods on identical work; writes results.jsonl, report.md, success_vs_rounds.png."""
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from activeintent.bench.report import plot_success_vs_rounds, write_report
    from activeintent.bench.runner import BenchOptions, run_bench
    from activeintent.intentions.registry import resolve_intention
    from activeintent.learners.registry import METHODS, check_method
    from activeintent.runner import RunOptions

    console = Console()
    try:
        method_list = [check_method(m) for m in (_split(methods) or list(METHODS))]
        intention_list = _split(intentions)
        for name in intention_list:
            resolve_intention(name, None)
        for f in intention_file or []:
            resolve_intention(None, f)
    except (ValueError, FileNotFoundError) as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    run = RunOptions(rounds=rounds, llm=llm, vlm=vlm, base_url=base_url, cache=cache, cache_mode=cache_mode,
                     executor=executor, retriever=retriever, save_videos=videos,
                     user=opt.user_options(user_beta, reaction_delay, false_stop, missed_stop))
    options = BenchOptions(methods=method_list, intentions=intention_list, intention_files=list(intention_file or []),
                           trials=trials, seed=seed, jobs=jobs, retry_errors=retry_errors, run=run)
    progress = Progress(TextColumn("[bold]bench"), BarColumn(), MofNCompleteColumn(), TextColumn("episodes"),
                        TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(), TextColumn("{task.description}"),
                        console=console)
    with progress:
        task = progress.add_task("", total=len(options.items()))

        def on_done(record: dict, finished: int, total: int) -> None:
            if record:
                mark = "[red]error[/red]" if record.get("error") else ("✓" if record.get("success") else "✗")
                progress.console.print(f"{mark} {record['method']} · {record['intention']} · trial {record['trial']}"
                                       + (f" — {record['error']}" if record.get("error") else ""))
                progress.update(task, completed=finished, description=f"last: {record['method']}/{record['intention']}")
            else:
                progress.update(task, completed=finished)

        try:
            records = run_bench(options, out, on_done)
        except ValueError as err:
            progress.stop()
            console.print(f"[red]error:[/red] {err}")
            raise typer.Exit(2) from None
    all_intentions = intention_list + list(intention_file or [])
    settings = {"trials": trials, "rounds": rounds, "llm": llm, "vlm": vlm or llm, "executor": executor,
                "retriever": retriever, "user": run.user.model_dump(), "seed": seed}
    from activeintent.bench.extras import extra_sections

    report = write_report(records, method_list, all_intentions, out, settings, extra_sections(records, method_list))
    plot_success_vs_rounds(records, method_list, rounds, out)
    console.print(report.read_text())
    console.print(f"[bold]report:[/bold] {report}  [bold]plot:[/bold] {out / 'success_vs_rounds.png'}")
