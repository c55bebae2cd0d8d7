"""`activeintent bench`: every method × intention × trial, resumable, with a report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from activeintent.bench.backends import check_backend
from activeintent.bench.coverage import EXPRESSIBLE, agreement, coverage_table, oracle_of
from activeintent.bench.report import plot_success_vs_signals, write_report
from activeintent.bench.runner import run_bench
from activeintent.bench.work import BenchConfig
from activeintent.cli import options as opt
from activeintent.goals.goal import parse_goal
from activeintent.goals.nodes import LATEST, speaking
from activeintent.goals.prior import load_prior
from activeintent.learners.registry import get_method
from activeintent.progress_lines import Eta, print_line
from activeintent.registry import load_plugin
from activeintent.runner import check_spec, for_method
from activeintent.spec import RunSpec
from activeintent.suites import is_held_out, resolve, suite_of
from activeintent.suites import suite as suite_names


def register(app: typer.Typer) -> None:
    app.command(name="bench")(bench)
    app.command(name="coverage")(coverage)


def _split(text: str) -> list[str]:
    return [t.strip() for t in text.split(",") if t.strip()]


# --preset NAME: a benchmark defined once. table1 = the paper's Table 1: its three methods on its
# four intentions, 5 trials each, K = 5 signals.
PRESETS = {"table1": {"methods": ["preference", "mllm", "mllm-llm"], "suite": "paper", "trials": 5, "budget": 5}}


# What each episode of a benchmark gets from its item (method, intention, trial), not from options.
BENCH_SETS = ("method", "intention", "intention_file", "seed", "test_seed", "video", "video_fps", "stop_when_done")


def _settings_shown(run: RunSpec, methods: list[str]) -> dict[str, str]:
    """Each learner setting as the methods ran with it: one value, or each method's."""
    by_name: dict[str, dict[str, object]] = {}
    for m in methods:
        for name, value in check_spec(for_method(run, m)).learner.settings.items():
            by_name.setdefault(name, {})[m] = value
    return {name: (str(next(iter(values.values()))) if len(set(map(str, values.values()))) == 1
                   else ", ".join(f"{m}: {v}" for m, v in values.items())) for name, values in by_name.items()}


def _apply_preset(preset: str, methods: str, intentions: str, budget: int | None) -> tuple[str, str, int]:
    """(methods, suite, trials) of the preset; options that would change what it measures are refused."""
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r}; valid presets: {', '.join(PRESETS)}")
    p = PRESETS[preset]
    if methods and _split(methods) != p["methods"]:
        raise ValueError(f"--preset {preset} runs the methods {', '.join(p['methods'])}; drop --methods")
    if intentions:
        raise ValueError(f"--preset {preset} runs the {p['suite']} suite; drop --intentions")
    if budget not in (None, p["budget"]):
        raise ValueError(f"--preset {preset} gives K = {p['budget']} signals; drop --budget")
    return ",".join(p["methods"]), p["suite"], p["trials"]


@opt.spec_command(exclude=BENCH_SETS)
def bench(
    given: dict,
    methods: Annotated[str, typer.Option("--methods", help="Comma-separated methods (default: bayes-preference, bayes-stop and the baselines)")] = "",
    suite: Annotated[str | None, typer.Option("--suite", help="Comma-separated suites: paper, library, heldout, heldout2, dev, truth-goals (default: paper, unless --intentions or --intention-file name what to run)")] = None,
    intentions: Annotated[str, typer.Option("--intentions", help="Comma-separated intentions (instead of --suite)")] = "",
    intention_file: Annotated[list[str] | None, typer.Option("--intention-file", help="Your own: path.py:NAME (repeatable); alone it runs just these, with --suite or --intentions it adds them")] = None,
    preset: Annotated[str | None, typer.Option("--preset", help="table1: the paper's Table 1 (preference, mllm, mllm-llm; the paper's four intentions; 5 trials; K = 5)")] = None,
    trials: Annotated[int | None, typer.Option("--trials", min=1, help="Episodes per method and intention (default 20; --preset table1: 5)")] = None,
    seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the benchmark: each trial's seeds come from it")] = 0,
    jobs: Annotated[int, typer.Option("--jobs", min=1, help="Episodes run in parallel (processes; with --backend ray and no cluster: the CPUs of the local Ray)")] = 1,
    backend: Annotated[str, typer.Option("--backend", help="local (process pool) | ray (one task per episode; docs/scaling.md)")] = "local",
    ray_address: Annotated[str | None, typer.Option("--ray-address", help="With --backend ray: cluster to use (e.g. auto); default $RAY_ADDRESS, else a local Ray")] = None,
    keep_episodes: Annotated[bool, typer.Option(help="Keep each episode's rounds.jsonl and summary.json")] = False,
    oracle: Annotated[bool, typer.Option(help="Add the oracle row: coverage of each intention by the goal language (≈ 10–20 s each, cached)")] = True,
    retry_errors: Annotated[bool, typer.Option(help="Re-run episodes that ended in an error")] = False,
    out: Annotated[Path, typer.Option("--out", help="Results folder; re-running with it resumes")] = Path("runs/bench"),
) -> None:
    """Compare methods on identical work under the honest protocol; writes results.jsonl,
    report.md and success_vs_signals.png."""
    from rich.console import Console

    console = Console()
    try:
        check_backend(backend)
        if preset is not None:
            methods, suite, preset_trials = _apply_preset(preset, methods, intentions, given.get("budget"))
            given["budget"] = PRESETS[preset]["budget"]
            trials = trials or preset_trials
        trials = trials or 20
        run = RunSpec.from_options(**given, video="none")
        method_list = _split(methods) or ["bayes-preference", "bayes-stop", "zero-signal", "random-query"]
        for m in method_list:
            check_spec(for_method(run, m))
        unused = sorted(set(run.learner.settings) - {k for m in method_list for k in get_method(m).own(run.learner.settings)})
        if unused:
            raise ValueError(f"{', '.join('--' + u.replace('_', '-') for u in unused)}: none of the methods "
                             f"({', '.join(method_list)}) has this setting")
        if suite is None:  # the paper suite only when nothing else says what to run
            suite = "" if intentions or intention_file else "paper"
        intention_list = _split(intentions) or [i for s in _split(suite) for i in suite_names(s)]
        labels = {f: resolve(None, f).name for f in intention_file or []}  # the report names each by its name
        for name in intention_list:
            if name in labels.values():
                spec = next(f for f, n in labels.items() if n == name)
                raise ValueError(f"{name!r} is the intention of --intention-file {spec}, which runs it already; "
                                 "drop it from --intentions")
            resolve(name)
        if not intention_list and not intention_file:
            raise ValueError("no intentions to run: give --suite, --intentions or --intention-file")
    except (ValueError, FileNotFoundError) as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    if opt.check_only():
        return
    options = BenchConfig(methods=method_list, intentions=intention_list, intention_files=list(intention_file or []),
                           trials=trials, seed=seed, jobs=jobs, backend=backend, ray_address=ray_address,
                           retry_errors=retry_errors,
                           keep_episodes=keep_episodes, run=run)
    names = {**{i: i for i in intention_list}, **labels}
    try:
        if console.is_terminal:
            records = _run_with_progress_bar(console, options, out, names)
        else:  # a log sees a live bar only at the end: a flushed line per episode instead
            records = run_bench(options, out, _ProgressLines(console, names), _RejectedLines(console))
    except ValueError as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    shared = {k: v for k, v in RunSpec(**run.model_dump(exclude={"learner"})).options().items()
              if k not in (*BENCH_SETS, "plugin")}
    shared.update(_settings_shown(run, method_list))
    settings = {**shared, "trials": trials, "seed": seed, **({"preset": preset} if preset else {})}
    all_intentions = intention_list + list(intention_file or [])
    ceiling = None
    if oracle:
        with speaking(run.learner.settings.get("language", LATEST)):  # the ceiling of the language the learners spoke
            ceiling = oracle_of({i: resolve(None, i) if ".py:" in i else resolve(i) for i in all_intentions},
                                progress=lambda text: print_line(console, text))
    report = write_report(records, method_list, all_intentions, out, settings, labels=labels, oracle=ceiling)
    plot_success_vs_signals(records, method_list, run.protocol.budget, out, labels=labels, settings=settings)
    console.print(report.read_text(), markup=False, soft_wrap=True)
    console.print(f"report: {out / 'report.md'}  plot: {out / 'success_vs_signals.png'}", markup=False)


def _outcome(record: dict) -> str:
    s = record.get("success")
    return "[red]error[/red]" if record.get("error") else ("–" if s is None else f"{s:.2f}")


class _RejectedLines:
    """``on_rejected``: say which lines of results.jsonl were not trusted, and why."""

    SHOWN = 5

    def __init__(self, console):
        self.console = console

    def __call__(self, rejected: list, where: Path) -> None:
        from rich.markup import escape

        print_line(self.console, f"[yellow]warning:[/yellow] {len(rejected)} line(s) of results.jsonl not trusted, "
                   f"moved to {escape(str(where))} (their episodes run again):")
        for r in rejected[:self.SHOWN]:
            print_line(self.console, f"  line {r.line}: {escape(r.reason)}")
        if len(rejected) > self.SHOWN:
            print_line(self.console, f"  … and {len(rejected) - self.SHOWN} more")


class _ProgressLines:
    """``on_done`` for a non-terminal: one flushed line per finished episode, with done/total,
    method, intention, trial, success@K, elapsed time and ETA."""

    def __init__(self, console, names: dict[str, str]):
        self.console, self.names, self.eta = console, names, None

    def __call__(self, record: dict, finished: int, total: int) -> None:
        from rich.markup import escape

        if self.eta is None:  # the first call: episodes already in the folder
            self.eta = Eta(total, done_before=finished)
            print_line(self.console, f"bench: {total - finished} episodes to run"
                       + (f" ({finished} of {total} already done)" if finished else ""))
        if not record:
            return
        error = f" — {escape(record['error'])}" if record.get("error") else ""
        print_line(self.console, f"{finished}/{total} · {record['method']} · "
                   f"{escape(self.names.get(record['intention'], record['intention']))} · trial {record['trial']} · "
                   f"success {_outcome(record)}{error} · {self.eta.text(finished)}")


def _run_with_progress_bar(console, options, out: Path, names: dict[str, str]) -> list[dict]:
    """A terminal: a live bar with ETA, a line above it per finished episode."""
    from rich.markup import escape
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    progress = Progress(TextColumn("[bold]bench"), BarColumn(), MofNCompleteColumn(), TextColumn("episodes"),
                        TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(), TextColumn("{task.description}"),
                        console=console)
    with progress:
        task = progress.add_task("", total=len(options.items()))

        def on_done(record: dict, finished: int, total: int) -> None:
            if record:
                name = escape(names.get(record["intention"], record["intention"]))
                progress.console.print(f"{_outcome(record)} {record['method']} · {name} · trial {record['trial']}"
                                       + (f" — {escape(record['error'])}" if record.get("error") else ""))
                progress.update(task, completed=finished, description=f"last: {record['method']}/{name}")
            else:
                progress.update(task, completed=finished)

        return run_bench(options, out, on_done, _RejectedLines(progress.console))


def coverage(
    suite: Annotated[str, typer.Option("--suite", help="Comma-separated suites: paper, library, heldout, heldout2, dev, truth-goals")] = "",
    intentions: Annotated[str, typer.Option("--intentions", help="Comma-separated intentions (instead of --suite)")] = "",
    intention_file: Annotated[list[str] | None, typer.Option("--intention-file", help="Your own: path.py:NAME (repeatable)")] = None,
    plugin: Annotated[list[str] | None, typer.Option("--plugin", help="Python file registering intentions, suites… (repeatable)")] = None,
    seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the scenes")] = 0,
    scenes: Annotated[int, typer.Option("--scenes", min=5, help="Scenes on which the best goal is chosen")] = 30,
    test_scenes: Annotated[int, typer.Option("--test-scenes", min=10, help="Further scenes on which its plan success is reported")] = 100,
    after_freeze: Annotated[bool, typer.Option("--after-freeze", help="Also print held-out intentions one by one (only after a freeze commit: docs/protocol.md)")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="print JSON")] = False,
    out: Annotated[Path | None, typer.Option("--out", help="Also write the table as JSON here")] = None,
    goal: Annotated[str | None, typer.Option("--goal", help="Score this goal of the language against each intention "
                                             "both ways (its plan satisfies the intention; the intention's plan "
                                             "satisfies it) instead of searching for the best goal")] = None,
    prior: Annotated[str, typer.Option("--prior", help="Whose bits L(z*) and prior rank: length (description length) | "
                                       "fitted (fitted to data/requests) | file:PATH (written by `prior fit`)")] = "length",
) -> None:
    """How well the goal language can say each intention: its best goal by behaviour (the goal
    whose own plan satisfies the intention on most test scenes), that plan's success — the
    oracle, the ceiling of every lang-* / decide-* learner — its description length, prior rank
    and whether the learner starts with it."""
    import json

    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    console = Console()
    try:
        for path in plugin or []:
            load_plugin(path)
        names = _split(intentions) or [i for s in _split(suite) for i in suite_names(s)]
        items = [resolve(n) for n in names] + [resolve(None, f) for f in intention_file or []]
        if not items:
            raise ValueError("nothing to measure: give --suite, --intentions or --intention-file")
        if prior == "uniform":
            raise ValueError("--prior uniform gives no bits to report: take length, fitted or file:PATH")

        load_prior(prior)  # a missing or malformed file is refused before the search
    except (ValueError, FileNotFoundError) as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    groups = [suite_of(n) for n in names] + ["file"] * len(intention_file or [])
    if goal is not None:
        if any(is_held_out(g) for g in groups) and not after_freeze:
            console.print("[red]error:[/red] held-out intentions are read only after a freeze (--after-freeze)")
            raise typer.Exit(2)
        try:
            z = parse_goal(goal)
        except (ValueError, IndexError, KeyError) as err:
            console.print(f"[red]error:[/red] --goal {escape(goal)!s}: not a goal of the language ({escape(str(err))})")
            raise typer.Exit(2) from None
        rows_ = [agreement(z, it, test_scenes, seed) for it in items]
        if as_json:
            typer.echo(json.dumps(rows_, indent=2, ensure_ascii=False))
            return
        for r in rows_:
            console.print(f"{escape(r['intention'])}: the goal's plan satisfies it on {r['goal_plan_satisfies_checker']:.2f}, "
                          f"its plan satisfies the goal on {r['checker_plan_satisfies_goal']:.2f} of {r['scenes']} "
                          f"feasible test scenes", highlight=False)
        return
    table = coverage_table(items, groups, seed=seed, scenes=scenes, test_scenes=test_scenes,
                           progress=lambda text: print_line(console, escape(text)) if not as_json else None,
                           prior=prior)
    if not after_freeze:  # per-intention rows of a held-out suite are the reading its rule forbids
        table["intentions"] = [r for r in table["intentions"] if not is_held_out(r["suite"])]
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(table, indent=2, ensure_ascii=False))
    if as_json:
        typer.echo(json.dumps(table, indent=2, ensure_ascii=False))
        return
    rows = Table("intention", "oracle", "best goal z*", "L(z*)", "prior rank", "start space", title=(
        f"Coverage: plan success of the best goal on {test_scenes} feasible test scenes (chosen on {scenes} others)"))
    for r in table["intentions"]:
        mark = "" if r["success"] >= EXPRESSIBLE else " [yellow](not expressible)[/yellow]"
        rows.add_row(escape(r["intention"]), f"{r['success']:.2f}{mark}", escape(r["goal"]), f"{r['bits']:.1f}",
                     str(r["prior_rank"]), "yes" if r["in_start_space"] else "no")
    console.print(rows)
    for s in table["suites"]:
        console.print(f"[bold]{escape(s['suite'])}[/bold]: oracle mean {s['mean']:.2f} over {s['n']} intentions "
                      f"(95 % bootstrap interval {s['ci'][0]:.2f}–{s['ci'][1]:.2f}); {s['expressible']} of {s['n']} "
                      f"≥ {EXPRESSIBLE}; median L(z*) {s['median_bits']:.1f} bits; {s['in_start_space']} in the start space",
                      highlight=False)
    hidden = sorted({g for g in groups if is_held_out(g)})
    if hidden and not after_freeze:
        console.print(f"(per-intention rows of {', '.join(hidden)} not shown: held out; --after-freeze shows them)")
