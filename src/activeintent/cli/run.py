"""`activeintent run`: one episode with a simulated user, shown round by round."""

from __future__ import annotations

from pathlib import Path

import typer

from activeintent.act.isolation import allow_unsafe_no_isolation
from activeintent.cli import options as opt
from activeintent.learners.registry import get_method
from activeintent.llm.base import ModelError
from activeintent.progress_lines import Eta, print_line
from activeintent.runner import DEFAULT_INTENTION, build_episode, check_spec
from activeintent.signals import answer_kind_from_dump
from activeintent.spec import RunSpec
from activeintent.suites import resolve


def register(app: typer.Typer) -> None:
    app.command(name="run")(run)


class LiveTable:
    """An episode observer: a rich table of rounds and a progress bar of signals. Row k shows
    round k: the y shown, the answer h, r, and then the estimate z *after* that answer (the
    learner's next z, or its final one) beside success@k, which scores that same estimate. A row
    is written once the estimate after it is known, so every round that happened has its row,
    scored or not (slow learners are scored at k = K only). With ``lines`` (stdout is not a
    terminal) it also prints one flushed line per row, and it always prints each failed model
    call as it happens (a learner that keeps going without its optional model would otherwise
    show the failure only in summary.json)."""

    def __init__(self, console, method: str, budget: int, seed: int, llm: str = "", lines: bool = False):
        from rich.markup import escape
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
        from rich.table import Table

        model = "no model" if llm in ("", "none") else f"model {escape(llm)}"
        self.table = Table(title=f"{escape(method)} on a hidden intention · budget {budget} signals · seed {seed} · "
                                 f"{model}", expand=not lines)
        for col, style in (("round", "bold"), ("y (shown)", ""), ("h (answer)", "magenta"), ("r (retrieved)", "dim"),
                           ("z (estimate after the answer)", "cyan"), ("success@k", "green")):
            self.table.add_column(col, style=style, overflow="fold")
        self.progress = Progress(TextColumn("signals"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                                 TimeElapsedColumn(), console=console)
        self.task = self.progress.add_task("signals", total=budget)
        self.console, self.budget, self.lines = console, budget, lines
        self.eta = None
        self.model_errors: list[str] = []
        self.rows = 0  # rounds written to the table
        self._learner = None
        self._held: dict | None = None  # the last round, until the estimate after it is known

    def started(self, episode) -> None:
        self._learner = episode.learner
        self.eta = Eta(self.budget)

    def _say(self, text: str) -> None:
        print_line(self.console, text)

    def _report_model_errors(self) -> None:
        from rich.markup import escape

        errors = list(getattr(self._learner, "proposal_errors", None) or [])
        for err in errors[len(self.model_errors):]:
            self._say(f"[red]model call failed[/red] (the learner goes on without it): {escape(err)}")
        self.model_errors = errors

    def _write(self, z_after: str | None) -> None:
        """The held round's row, with the estimate after its answer."""
        from rich.markup import escape

        row, self._held = self._held, None
        if row is None:
            return
        z = "–" if z_after is None else escape(z_after)
        rate = row["rate"]
        self.table.add_row(row["round"], row["goals"], row["answer"], row["retrieved"], z, rate)
        self.rows += 1
        if self.lines:
            k = row["k"]
            scored = f" · success@{k} = {rate}" if k is not None and rate else ""
            eta = f" · {self.eta.text(k)}" if k is not None and self.eta is not None else ""
            self._say(f"signal {k if k is not None else '–'}/{self.budget} · round {row['round']} · answer "
                      f"{row['answer']} · z after it = “{z}”{scored}{eta}")

    def final(self, result) -> None:
        """The held round gets the episode's final z; then the last row: the z and goal the
        episode ends with, on the test scene it was shown on (numbered from 1)."""
        from rich.markup import escape

        self._write(result.final_z)
        rate = "n/a" if result.success is None else f"{result.success:.2f}"
        where = "" if result.final_scene is None else f"test scene {result.final_scene + 1}: "
        self.table.add_row("final", escape(where + result.final_goal), "", "", escape(result.final_z), rate)

    def answered(self, log) -> None:
        from rich.markup import escape

        # this round's z was estimated after the previous round's answer: that row is complete
        self._write(log.z)
        h = log.answer
        kind = answer_kind_from_dump(h)
        text = f"stop at {h['stop_time']:.2f} s" if kind == "stop" else kind.replace("_", " ")
        if not log.counted:
            text += " (free)"
        goals = "\n".join(f"{lab}: {g}" for lab, g in zip(log.labels, log.goals, strict=False))
        self._held = {"round": str(log.round), "goals": escape(goals), "answer": text,
                      "retrieved": escape(log.retrieved or ""), "rate": "",
                      "k": log.signals_used if log.counted else None}
        self._report_model_errors()
        self.progress.update(self.task, completed=log.signals_used)

    def scored(self, k: int, rate) -> None:
        shown = "–" if rate is None else f"{rate:.2f}"
        if self._held is not None and self._held["k"] == k:
            self._held["rate"] = shown
        elif k == 0:
            self.table.add_row("0", "", "", "", "(prior, before any signal)", shown)
            if self.lines:
                self._say(f"signal 0/{self.budget} · prior, before any signal · success@0 = {shown}")

    def flush(self) -> None:
        """An episode that ended early (a model error): the last round still gets its row."""
        self._write(None)


@opt.spec_command()
def run(
    given: dict,
    unsafe_no_isolation: opt.UnsafeNoIsolation = False,
    out: opt.Out = None,
) -> None:
    """Run one episode: the learner asks, a simulated user with a hidden intention answers."""
    from contextlib import nullcontext

    from rich.console import Group
    from rich.live import Live
    from rich.markup import escape

    console = plain_console()
    if unsafe_no_isolation:
        allow_unsafe_no_isolation()
    try:
        spec = RunSpec.from_options(**given)
    except ValueError as err:
        console.print(f"[red]error:[/red] {escape(str(err))}", soft_wrap=True)
        raise typer.Exit(2) from None
    p, method, who = spec.protocol, spec.learner.method, spec.user
    intention, intention_file, llm = who.intention, who.intention_file, spec.models.llm
    note = None
    if not {"test_scenes", "test_pool"} & set(given) and method_asks_a_model(method):
        # Every test scene is a model call (and a planner call) for these learners: a curve of
        # 10 scenes at k = 0…K and a pool of 70 at K took most of an hour on 2 cores.
        spec = spec.with_options(curve=False, test_pool=0)
        note = (f"{method} asks the model for every test scene: scored at k = {p.budget} only, on the "
                f"{p.test_scenes} curve scenes (--test-pool N adds the pool and the curve; bench scores the whole protocol)")
    name = intention or (Path(intention_file.split(":")[0]).stem if intention_file else DEFAULT_INTENTION)
    out_dir = out or Path("runs") / f"{method}-{name}-seed{p.seed}"
    live = LiveTable(console, method, p.budget, p.seed, llm=llm, lines=not console.is_terminal)
    if opt.check_only():
        try:
            check_spec(spec)
            resolve(intention or (None if intention_file else DEFAULT_INTENTION), intention_file)
        except (ValueError, FileNotFoundError) as err:
            console.print(f"[red]error:[/red] {escape(str(err))}", soft_wrap=True)
            raise typer.Exit(2) from None
        return
    if note:
        console.print(note, soft_wrap=True, highlight=False, markup=False)
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
        console.print(f"[red]error:[/red] {escape(str(err))}", soft_wrap=True)
        raise typer.Exit(2) from None
    except ModelError as err:
        live.flush()
        if live.rows and not console.is_terminal:
            console.print(live.table)  # the rounds that happened
        console.print(f"[red]model error:[/red] {escape(str(err))}", soft_wrap=True)
        raise typer.Exit(3) from None
    finally:
        if "episode" in locals():
            episode.env.close()
    if not console.is_terminal:
        console.print(live.table)
    video_note = final_video_note(spec, episode, out_dir)
    if video_note:
        console.print(video_note, soft_wrap=True, highlight=False)
    if result.error:
        console.print(f"[red]episode ended early:[/red] {escape(result.error)} (log: {out_dir})", soft_wrap=True)
        raise typer.Exit(3)
    errors = result.learner_stats.get("proposal_errors") or []
    if errors and result.llm_calls == 0:
        console.print(f"[red]model error:[/red] the model never answered ({escape(errors[0])})", soft_wrap=True)
        raise typer.Exit(3)
    rate = "n/a (no test scene feasible)" if result.success is None else f"{result.success:.2f}"
    console.print(
        f"success@{result.budget} = {rate} on {result.test_scored or 0} test scenes "
        f"({result.test_excluded} excluded: the hidden intention cannot be shown there) · "
        f"{result.method} on {result.intention} · final z = “{escape(result.final_z)}” · {result.signals_used} signals "
        f"{dict(result.answers)} · {model_summary(llm, result.llm_calls, errors)} · {result.wall_s:.0f} s · "
        f"{out_dir}/summary.json", soft_wrap=True)


def method_asks_a_model(method: str) -> bool:
    """Whether the method's learner needs a language model (an unknown name: False, refused later)."""
    try:
        return bool(get_method(method).needs_llm)
    except (KeyError, ValueError):
        return False


def plain_console():
    """The console of commands that print user strings: no emoji codes (a model spec such as
    ``openai:x`` followed by ``:`` must not become an emoji), and, when stdout is not a terminal
    (a pipe, a log), tables as wide as they need (up to 400 columns) instead of 80 columns."""
    from rich.console import Console

    console = Console(emoji=False)
    if not console.is_terminal:
        console.width = 400
    return console


def final_video_note(spec, episode, out_dir: Path) -> str | None:
    """Why ``--video final`` (or ``all``) left no final.gif, or None when it is there (or was not asked)."""
    if spec.protocol.video == "none" or (out_dir / "final.gif").exists():
        return None
    if not episode.env.renders:
        return (f"no final.gif: the {spec.env.name} env draws no pictures (videos need --env pybullet); "
                "the final attempt is described in summary.json")
    return "no final.gif: no test scene was run in physics for the final attempt (see summary.json)"


def model_summary(llm: str, calls: int, errors: list[str]) -> str:
    """What the summary line says about the model: none, or its calls and, in red, the failed ones."""
    from rich.markup import escape

    if llm == "none":
        return "no model (--llm none)"
    text = f"model {escape(llm)}: {calls} calls"
    if errors:
        text += f", [red]{len(errors)} failed[/red] (first: {escape(errors[0])})"
    return text
