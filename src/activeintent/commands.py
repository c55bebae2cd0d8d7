"""`activeintent run`: one episode with a simulated user, shown round by round."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from activeintent import options as opt
from activeintent.runner import DEFAULT_METHOD


def register(app: typer.Typer) -> None:
    app.command(name="run")(run)


def run(
    method: Annotated[str, typer.Option("--method", help="preference | mllm | mllm-llm | bayes-preference | bayes-stop")] = DEFAULT_METHOD,
    intention: opt.Intention = None,
    intention_file: opt.IntentionFile = None,
    rounds: opt.Rounds = 5,
    seed: opt.Seed = 0,
    test_scenes: Annotated[int, typer.Option("--test-scenes", min=1, help="Fresh scenes the final answer is tested on")] = 1,
    llm: opt.Llm = "embedded",
    vlm: opt.Vlm = None,
    base_url: opt.BaseUrl = None,
    cache: opt.Cache = None,
    cache_mode: opt.CacheMode = "record",
    executor: opt.Executor = "plan",
    retriever: opt.Retriever = "symbolic",
    epsilon: Annotated[float, typer.Option("--epsilon", help="ε: seconds before the stop for image I_b")] = 2.0,
    user_beta: opt.UserBeta = float("inf"),
    reaction_delay: opt.ReactionDelay = "0.5,0.15",
    false_stop: opt.FalseStop = 0.0,
    missed_stop: opt.MissedStop = 0.0,
    design_scenes: Annotated[bool, typer.Option(help="Let the learner choose each round's objects")] = True,
    out: Annotated[Path | None, typer.Option("--out", help="Output folder (default runs/<method>-<intention>-seed<S>)")] = None,
) -> None:
    """Run one episode: the learner asks, a simulated user with a hidden intention answers."""
    from rich.console import Console, Group
    from rich.live import Live
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.table import Table

    from activeintent.llm.base import ModelError
    from activeintent.runner import RunOptions, build_episode

    console = Console()
    options = RunOptions(
        method=method, intention=intention, intention_file=intention_file, rounds=rounds, seed=seed,
        test_scenes=test_scenes, llm=llm, vlm=vlm, base_url=base_url, cache=cache, cache_mode=cache_mode,
        executor=executor, retriever=retriever, epsilon=epsilon, design_scenes=design_scenes,
        user=opt.user_options(user_beta, reaction_delay, false_stop, missed_stop),
    )
    name = intention or (Path(intention_file.split(":")[0]).stem if intention_file else "color-match")
    out_dir = out or Path("runs") / f"{method}-{name}-seed{seed}"

    table = Table(title=f"{method} on a hidden intention · {rounds} rounds · seed {seed}", expand=True)
    for col, style in (("round", "bold"), ("z (estimated intention)", "cyan"), ("y (goal)", ""),
                       ("h (signal)", "magenta"), ("r (retrieved)", "dim")):
        table.add_column(col, style=style, overflow="fold")
    progress = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                        TimeElapsedColumn(), console=console)
    task = progress.add_task("signals", total=rounds)

    def on_round(log) -> None:
        h = log.feedback
        signal = h.get("choice") if h.get("kind") == "preference" else (
            "new scene" if h.get("new_scene") else "no stop" if h.get("stop_time") is None
            else f"stop at {h['stop_time']:.2f} s (step {(h.get('step_index') or 0) + 1})")
        table.add_row(str(log.round), log.preference, "\n".join(log.goals), signal, log.retrieved or "")
        progress.update(task, completed=log.signals_used)  # new-scene answers are free up to a cap

    try:
        with console.status("loading models and simulator…"):
            episode = build_episode(options, out_dir, on_round=on_round)
        with Live(Group(table, progress), console=console, refresh_per_second=4):
            result = episode.run()
    except (ValueError, FileNotFoundError) as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    except ModelError as err:
        console.print(f"[red]model error:[/red] {err}")
        raise typer.Exit(3) from None
    if result.error:
        # The episode log is kept; a model that failed for good is still a failed run.
        console.print(f"[red]episode ended early:[/red] {result.error} (log: {out_dir})")
        raise typer.Exit(3)
    verdict = "[green]SUCCESS[/green]" if result.success else "[red]FAILURE[/red]"
    console.print(
        f"{verdict} {result.method} on {result.intention}: final z = “{result.final_preference}” · "
        f"{result.signals_used} signals · {result.llm_calls} model calls · {result.wall_s:.0f} s · {out_dir}/summary.json"
    )
