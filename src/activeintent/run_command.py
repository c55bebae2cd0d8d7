"""`activeintent run`: one episode with a simulated user, shown round by round."""

from __future__ import annotations

from pathlib import Path

import typer

from activeintent import options as opt
from activeintent.options import D


def register(app: typer.Typer) -> None:
    app.command(name="run")(run)


class LiveTable:
    """An episode observer: a rich table of rounds (z, y, h, r) and a progress bar of signals.
    With ``lines`` (stdout is not a terminal) it also prints one flushed line per signal, and it
    always prints each failed model call as it happens (a learner that keeps going without its
    optional model would otherwise show the failure only in summary.json)."""

    def __init__(self, console, method: str, budget: int, seed: int, llm: str = "", lines: bool = False):
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
        from rich.table import Table

        model = "no model" if llm in ("", "none") else f"model {llm}"
        self.table = Table(title=f"{method} on a hidden intention · budget {budget} signals · seed {seed} · {model}",
                           expand=True)
        for col, style in (("round", "bold"), ("z (estimated intention)", "cyan"), ("y (shown)", ""),
                           ("h (answer)", "magenta"), ("r (retrieved)", "dim"), ("success@k", "green")):
            self.table.add_column(col, style=style, overflow="fold")
        self.progress = Progress(TextColumn("signals"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                                 TimeElapsedColumn(), console=console)
        self.task = self.progress.add_task("signals", total=budget)
        self.console, self.budget, self.lines = console, budget, lines
        self.eta = None
        self.model_errors: list[str] = []
        self._learner = None
        self._pending = None

    def started(self, episode) -> None:
        from activeintent.progress_lines import Eta

        self._learner = episode.learner
        self.eta = Eta(self.budget)

    def _say(self, text: str) -> None:
        from activeintent.progress_lines import print_line

        print_line(self.console, text)

    def _report_model_errors(self) -> None:
        from rich.markup import escape

        errors = list(getattr(self._learner, "proposal_errors", None) or [])
        for err in errors[len(self.model_errors):]:
            self._say(f"[red]model call failed[/red] (the learner goes on without it): {escape(err)}")
        self.model_errors = errors

    def final(self, result) -> None:
        """The last row: the z and goal the episode ends with (the summary line's final z), on the
        first test scene that can show the intention."""
        from rich.markup import escape

        rate = "n/a" if result.success is None else f"{result.success:.2f}"
        where = "" if result.final_scene is None else f"test scene {result.final_scene + 1}: "
        self.table.add_row("final", escape(result.final_z), escape(where + result.final_goal), "", "", rate)

    def answered(self, log) -> None:
        from rich.markup import escape

        from activeintent.signals import answer_kind_from_dump

        h = log.answer
        kind = answer_kind_from_dump(h)
        text = f"stop at {h['stop_time']:.2f} s" if kind == "stop" else kind.replace("_", " ")
        if not log.counted:
            text += " (free)"
        goals = "\n".join(f"{lab}: {g}" for lab, g in zip(log.labels, log.goals, strict=False))
        self._pending = [str(log.round), escape(log.z), escape(goals), text, escape(log.retrieved or "")]
        self._report_model_errors()
        if not log.counted:
            self.table.add_row(*self._pending, "")
            if self.lines:
                self._say(f"round {log.round} · answer {text} · z = “{escape(log.z)}”")
            self._pending = None
        self.progress.update(self.task, completed=log.signals_used)

    def scored(self, k: int, rate) -> None:
        shown = "–" if rate is None else f"{rate:.2f}"
        if self._pending is not None:
            self.table.add_row(*self._pending, shown)
            if self.lines:
                round_, z, _, answer, _ = self._pending
                self._say(f"signal {k}/{self.budget} · round {round_} · answer {answer} · z = “{z}” · "
                          f"success@{k} = {shown} · {self.eta.text(k)}")
            self._pending = None
        elif k == 0:
            self.table.add_row("0", "(prior, before any signal)", "", "", "", shown)
            if self.lines:
                self._say(f"signal 0/{self.budget} · prior, before any signal · success@0 = {shown}")


def run(
    method: opt.Method = D.method,
    intention: opt.Intention = None,
    intention_file: opt.IntentionFile = None,
    plugin: opt.Plugin = None,
    budget: opt.Budget = D.budget,
    seed: opt.Seed = D.seed,
    test_seed: opt.TestSeed = None,
    test_scenes: opt.TestScenes = D.test_scenes,
    test_pool: opt.TestPool = D.test_pool,
    env: opt.Env = D.env,
    user: opt.User = D.user,
    new_scene: opt.NewScene = D.new_scene,
    prior: opt.Prior = D.prior,
    scenes: opt.Scenes = D.scenes,
    llm: opt.Llm = D.llm,
    vlm: opt.Vlm = None,
    base_url: opt.BaseUrl = None,
    cache: opt.Cache = None,
    cache_mode: opt.CacheMode = D.cache_mode,
    executor: opt.Executor = D.executor,
    unsafe_no_isolation: opt.UnsafeNoIsolation = False,
    retriever: opt.Retriever = D.retriever,
    epsilon: opt.Epsilon = D.epsilon,
    early_threshold: opt.EarlyThreshold = D.early_threshold,
    variant: opt.Variant = D.variant,
    video: opt.Video = D.video,
    design_scenes: bool = typer.Option(D.design_scenes, help="Let the learner choose each round's objects"),
    out: opt.Out = None,
) -> None:
    """Run one episode: the learner asks, a simulated user with a hidden intention answers."""
    from contextlib import nullcontext

    from rich.console import Console, Group
    from rich.live import Live
    from rich.markup import escape

    from activeintent.llm.base import ModelError
    from activeintent.progress_lines import print_line
    from activeintent.runner import DEFAULT_INTENTION, build_episode

    console = Console()
    if unsafe_no_isolation:
        from activeintent.act.isolation import allow_unsafe_no_isolation

        allow_unsafe_no_isolation()
    try:
        spec = opt.run_spec(
            method=method, intention=intention, intention_file=intention_file, plugins=plugin, budget=budget,
            seed=seed, test_seed=test_seed, test_scenes=test_scenes, test_pool=test_pool, env=env, user=user, new_scene=new_scene, prior=prior, scenes=scenes, llm=llm,
            vlm=vlm, base_url=base_url, cache=cache, cache_mode=cache_mode, executor=executor,
            retriever=retriever, epsilon=epsilon, early_threshold=early_threshold, variant=variant, video=video,
            design_scenes=design_scenes,
            )
    except ValueError as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    name = intention or (Path(intention_file.split(":")[0]).stem if intention_file else DEFAULT_INTENTION)
    out_dir = out or Path("runs") / f"{method}-{name}-seed{seed}"
    live = LiveTable(console, method, budget, seed, llm=llm, lines=not console.is_terminal)
    if opt.check_only():
        try:
            from activeintent.runner import check_spec
            from activeintent.suites import resolve

            check_spec(spec)
            resolve(intention or (None if intention_file else DEFAULT_INTENTION), intention_file)
        except (ValueError, FileNotFoundError) as err:
            console.print(f"[red]error:[/red] {err}")
            raise typer.Exit(2) from None
        return
    try:
        if live.lines:  # a log sees a live display only at the end: plain lines instead
            print_line(console, f"loading models and simulator… ({'no model' if llm == 'none' else 'model ' + llm})")
        with console.status("loading models and simulator…"):
            episode = build_episode(spec, out_dir, observers=[live])
        shown = nullcontext() if live.lines else Live(Group(live.table, live.progress), console=console,
                                                      refresh_per_second=4)
        with shown:
            result = episode.run()
            live.final(result)
    except (ValueError, FileNotFoundError) as err:
        console.print(f"[red]error:[/red] {err}")
        raise typer.Exit(2) from None
    except ModelError as err:
        console.print(f"[red]model error:[/red] {err}")
        raise typer.Exit(3) from None
    finally:
        if "episode" in locals():
            episode.env.close()
    if not console.is_terminal:
        console.print(live.table)
    if result.error:
        console.print(f"[red]episode ended early:[/red] {result.error} (log: {out_dir})")
        raise typer.Exit(3)
    errors = result.learner_stats.get("proposal_errors") or []
    if errors and result.llm_calls == 0:
        console.print(f"[red]model error:[/red] the model never answered ({escape(errors[0])})")
        raise typer.Exit(3)
    rate = "n/a (no test scene feasible)" if result.success is None else f"{result.success:.2f}"
    console.print(
        f"success@{result.budget} = {rate} on {result.test_scored or 0} test scenes "
        f"({result.test_excluded} excluded: the hidden intention cannot be shown there) · "
        f"{result.method} on {result.intention} · final z = “{escape(result.final_z)}” · {result.signals_used} signals "
        f"{dict(result.answers)} · {model_summary(llm, result.llm_calls, errors)} · {result.wall_s:.0f} s · "
        f"{out_dir}/summary.json", soft_wrap=True)


def model_summary(llm: str, calls: int, errors: list[str]) -> str:
    """What the summary line says about the model: none, or its calls and, in red, the failed ones."""
    from rich.markup import escape

    if llm == "none":
        return "no model (--llm none)"
    text = f"model {escape(llm)}: {calls} calls"
    if errors:
        text += f", [red]{len(errors)} failed[/red] (first: {escape(errors[0][:120])})"
    return text
