"""`activeintent serve`: the human-in-the-loop web app; `activeintent study-export`: one
table of a study's sessions."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from activeintent.cli import options as opt
from activeintent.intentions.registry import IntentionError
from activeintent.learners.registry import get_method
from activeintent.protocol import DEFAULT_BUDGET
from activeintent.runner import check_spec
from activeintent.spec import RunSpec
from activeintent.suites import resolve as resolve_intention
from activeintent.web.basics import VIDEO_SIZE_TEXT
from activeintent.web.export import collect_sessions, corpus_rows, write_table
from activeintent.web.study import StudyFileError, load_study


class ShowEstimate(StrEnum):
    hidden = "hidden"
    after_answer = "after-answer"
    always = "always"


# What each session gets from the server, not from options.
SESSION_SETS = ("test_seed", "video", "video_fps", "curve", "stop_when_done")


def register(app: typer.Typer) -> None:
    app.command(name="serve")(serve)
    app.command(name="study-export")(study_export)


@opt.spec_command(exclude=SESSION_SETS)
def serve(
    given: dict,
    host: Annotated[str, typer.Option("--host", help="Address to bind (loopback unless told otherwise)")] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", min=0, max=65535, help="TCP port")] = 8000,
    method: Annotated[str | None, typer.Option("--method", help="preference | mllm | mllm-llm | bayes-preference | bayes-stop | lang-preference | lang-stop (default bayes-preference; with --study: the study file's conditions)")] = None,
    intention: Annotated[str | None, typer.Option("--intention", help="Assign this rule to every participant (shown on the start page; success is scored against it). Without it each participant picks their own rule and success is not scored (free-rule design)")] = None,
    intention_file: Annotated[str | None, typer.Option("--intention-file", help="Assign your own rule: path.py:NAME (as --intention)")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Session n runs with seed + n")] = 0,
    out: Annotated[Path, typer.Option("--out", help="Sessions are saved in OUT/<session-id>/")] = Path("runs/web"),
    show_estimate: Annotated[ShowEstimate | None, typer.Option("--show-estimate", help="The learner's current guess: never shown (hidden, the default), shown between rounds after each answer (after-answer), or above the videos from round 2 on (always); never before the first answer")] = None,
    study: Annotated[Path | None, typer.Option("--study", help="A study file (.json or .toml): consent text, completion code and redirect, and the conditions (method × rule × guess display) participants are assigned to in a balanced way; replaces --method, --intention and --show-estimate")] = None,
    video_size: opt.VideoSize = VIDEO_SIZE_TEXT,
    llm: Annotated[str | None, typer.Option("--llm", help="LLM: embedded | gguf:/path.gguf | openai:<model> | none (default: embedded for methods that need a model, none for the others)")] = None,
    answer_timeout: Annotated[float, typer.Option("--answer-timeout", min=1.0, help="Seconds to wait for one answer before a session is abandoned")] = 1800.0,
    max_sessions: Annotated[int, typer.Option("--max-sessions", min=1, help="Sessions in progress at once")] = 4,
    max_sessions_per_client: Annotated[int, typer.Option("--max-sessions-per-client", min=1, help="Sessions in progress at once from one client address")] = 2,
    max_new_sessions_per_hour: Annotated[int, typer.Option("--max-new-sessions-per-hour", min=1, help="Sessions one client address may start per hour")] = 30,
    idle_timeout: Annotated[float, typer.Option("--idle-timeout", min=0.1, help="Minutes without a request from a session's page before it is cancelled and its slot freed")] = 3.0,
    reconnect_grace: Annotated[float, typer.Option("--reconnect-grace", min=1.0, help="Seconds a session whose page was closed (its unload beacon) waits for a page of it to come back before it is cancelled and its slot freed")] = 20.0,
    shared_client: Annotated[list[str] | None, typer.Option("--shared-client", help="An address or network (CIDR) that several participants share, e.g. a lab's PCs behind one NAT address or a proxy: no per-client session limits for it (--max-sessions still holds). Repeatable")] = None,
    max_request_kb: Annotated[int, typer.Option("--max-request-kb", min=1, help="Largest request body in KiB")] = 128,
    events_quota_mb: Annotated[float, typer.Option("--events-quota-mb", min=0.01, help="Largest events.jsonl the browser may fill per session, in MiB")] = 5.0,
    header_timeout: Annotated[float, typer.Option("--header-timeout", min=0.5, help="Seconds a new or idle connection has to send a whole request head before it is closed")] = 10.0,
    body_timeout: Annotated[float, typer.Option("--body-timeout", min=0.5, help="Seconds a request body has to arrive (408 after)")] = 30.0,
    max_connections_per_client: Annotated[int, typer.Option("--max-connections-per-client", min=1, help="Connections open at once from one client address (a browser uses up to 6)")] = 32,
    max_connections: Annotated[int, typer.Option("--max-connections", min=8, help="Connections open at once in all; never more than the file-descriptor limit leaves after a reserve for the sessions")] = 1000,
) -> None:
    """Serve the study: participants give the method's signal (preference, stop, or a plug-in's with a page) in the browser.

    Each session is saved like a simulated run (summary.json, rounds.jsonl, videos) in OUT/<session-id>/, plus events.jsonl with every UI event. The JSON API is described at /openapi.json.
    """
    from rich.console import Console

    # lazy: FastAPI, Starlette and uvicorn load only for serve (~0.5 s)
    from activeintent.web import transport
    from activeintent.web.limits import Limits
    from activeintent.web.server import create_app, page_signal, runner_builder
    from activeintent.web.session import StudyConfig

    size = tuple(video_size)  # parsed by the option
    extra = {k: v for k, v in given.items() if k != "budget"}
    rounds = given.get("budget", DEFAULT_BUDGET)
    study_file = None
    if study is not None:
        given = [name for name, v in (("--method", method), ("--intention", intention),
                                      ("--intention-file", intention_file), ("--show-estimate", show_estimate)) if v]
        if given:
            raise typer.BadParameter(f"{', '.join(given)}: set per condition in the study file, not here",
                                     param_hint="--study")
        try:
            study_file = load_study(study)
        except StudyFileError as err:
            raise typer.BadParameter(str(err), param_hint="--study") from None
        rounds = study_file.rounds or rounds
        cells = [(c.name, c.method, c.intention, c.intention_file, c.show_estimate) for c in study_file.conditions]
    else:
        cells = [("single", method or "bayes-preference", intention, intention_file,
                  (show_estimate or ShowEstimate.hidden).value)]
    configs: dict[str, StudyConfig] = {}
    models: dict[str, str] = {}  # condition -> its --llm: a method that needs no model gets none
    for name, m, rule_name, rule_file, shown in cells:
        try:
            models[name] = llm or ("embedded" if get_method(m).needs_llm else "none")
            # the spec and the assigned rule are checked now so a typo fails before anyone opens the page
            run = RunSpec.from_options(method=m, budget=rounds, intention=rule_name, intention_file=rule_file,
                               llm=models[name], seed=seed, **extra)
            check_spec(run)
            rule = resolve_intention(rule_name, rule_file) if rule_name or rule_file else None
            signal = page_signal(get_method(m).signal).name
            configs[name] = StudyConfig(
                run=run, signal=signal, intention_name=rule.name if rule else None,
                intention_description=(rule.description or rule.name) if rule else None, show_estimate=shown,
                video_size=size, out_dir=out, answer_timeout=answer_timeout, max_sessions=max_sessions)
        except (ValueError, IntentionError, FileNotFoundError) as err:
            where = f"condition {name}: " if study_file else ""
            raise typer.BadParameter(where + str(err)) from None
    config = next(iter(configs.values()))
    from pydantic import ValidationError

    try:
        limits = Limits(
            max_sessions_per_client=max_sessions_per_client,
            max_new_sessions_per_hour=max_new_sessions_per_hour, idle_timeout=idle_timeout * 60,
            max_body_bytes=max_request_kb * 1024, events_quota_bytes=int(events_quota_mb * 2**20),
            header_timeout=header_timeout, body_timeout=body_timeout,
            max_connections_per_client=max_connections_per_client, max_connections=max_connections,
            reconnect_grace=reconnect_grace, shared_clients=list(shared_client or []))
    except ValidationError as err:
        raise typer.BadParameter("; ".join(e["msg"].removeprefix("Value error, ") for e in err.errors()),
                                 param_hint="--shared-client") from None
    if opt.check_only():
        return
    conditions = ({name: (c, runner_builder(c)) for name, c in configs.items()}
                  if study_file else None)
    first = next(iter(configs))
    try:
        app = create_app(config, runner_builder(config), limits=limits, study=study_file,
                         conditions=conditions)
    except ValueError as err:  # e.g. an unreadable OUT/assignment.json
        raise typer.BadParameter(str(err), param_hint="--out") from None
    console = Console()
    shown = "localhost" if host in ("127.0.0.1", "::1") else host
    if study_file is not None:
        console.print(f"[bold]activeintent study[/] from {study}: {len(configs)} conditions, {rounds} rounds; "
                      f"sessions saved in {out}/")
        for name, c in configs.items():
            console.print(f"  {name}: {c.run.learner.method} ({c.signal}), {c.design} "
                          f"{c.intention_name or ''}, guess {c.show_estimate}, model {models[name]}")
        console.print("Participants are assigned to the least-filled condition (counts in "
                      f"{out}/assignment.json); a participant ID is "
                      + ("required" if study_file.require_pid else "optional") + " (?pid=… or ?PROLIFIC_PID=…).")
        console.print(f"Open http://{shown}:{port}/?pid=TEST — API schema at /openapi.json. Ctrl-C stops.")
        if host not in ("127.0.0.1", "localhost", "::1"):
            console.print(f"[yellow]Listening on {host}: anyone who can reach this address can take part.[/]")
        transport.serve(app, host=host, port=port)
        return
    signal, rule = config.signal, config.intention_name
    method = config.run.learner.method
    console.print(f"[bold]activeintent study[/]: {method} ({signal} signal), {rounds} rounds; "
                  f"sessions saved in {out}/")
    if rule is not None:
        console.print(f"Design: assigned rule [bold]{rule}[/] — participants are told "
                      f"\"{config.intention_description}\"; success is scored against it.")
    else:
        console.print("Design: free rule — each participant picks their own rule; success is not scored "
                      "(their own verdict is in the questionnaire).")
    console.print(f"The learner's guess: {config.show_estimate}; model {models[first]}; "
                  f"videos {size[0]}×{size[1]} px.")
    console.print(f"Open http://{shown}:{port}/ — API schema at /openapi.json. Ctrl-C stops.")
    if host not in ("127.0.0.1", "localhost", "::1"):
        console.print(f"[yellow]Listening on {host}: anyone who can reach this address can take part.[/]")
    transport.serve(app, host=host, port=port)


def study_export(
    out_dir: Annotated[Path, typer.Argument(help="The --out folder of `activeintent serve` (one sub-folder per session)")],
    to: Annotated[Path, typer.Option("--to", help="The table to write: FILE.csv (one row per session) or FILE.jsonl (one object per session)")],
    corpus: Annotated[Path | None, typer.Option("--corpus", help="Also write the free-rule sessions' rules in their own words as a corpus of requests (JSON lines, data/requests' format; translate each into a goal, then `prior fit`)")] = None,
) -> None:
    """One table of a study: per session the participant code, design, rule, answers per round,
    timings, success (assigned-rule sessions only) and the questionnaire."""
    from rich.console import Console

    if not out_dir.is_dir():
        raise typer.BadParameter(f"{out_dir} is not a folder", param_hint="OUT_DIR")
    if to.suffix.lower() not in (".csv", ".jsonl"):
        raise typer.BadParameter(f"{to.name}: the table is written as .csv or .jsonl", param_hint="--to")
    sessions, skipped = collect_sessions(out_dir)
    write_table(sessions, to)
    if corpus is not None:
        import json
        import os

        rows = corpus_rows(sessions)
        corpus.parent.mkdir(parents=True, exist_ok=True)
        tmp = corpus.with_name(f".{corpus.name}.{os.getpid()}.tmp")
        tmp.write_text("".join(json.dumps(r, ensure_ascii=False) + "\n" for r in rows))
        os.replace(tmp, corpus)
        Console().print(f"{len(rows)} free-rule rules written to {corpus} (assigned-rule sessions left out)")
    console = Console(stderr=True)
    for folder, why in skipped:
        console.print(f"[yellow]skipped {folder.name}[/]: {why}")
    answered = sum(1 for s in sessions if s["questionnaire_submitted"] is not None)
    Console().print(f"{len(sessions)} sessions ({answered} with a questionnaire) written to {to}")
