"""`activeintent serve`: the human-in-the-loop web app."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from activeintent import options as opt
from activeintent.options import D


def register(app: typer.Typer) -> None:
    app.command(name="serve")(serve)


def serve(
    host: Annotated[str, typer.Option("--host", help="Address to bind (loopback unless told otherwise)")] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", min=0, max=65535, help="TCP port")] = 8000,
    method: Annotated[str, typer.Option("--method", help="preference | mllm | mllm-llm | bayes-preference | bayes-stop")] = "bayes-preference",
    rounds: opt.Budget = D.budget,
    intention: opt.Intention = None,
    intention_file: opt.IntentionFile = None,
    seed: Annotated[int, typer.Option("--seed", help="Session n runs with seed + n")] = 0,
    out: Annotated[Path, typer.Option("--out", help="Sessions are saved in OUT/<session-id>/")] = Path("runs/web"),
    show_estimate: Annotated[bool, typer.Option("--show-estimate/--hide-estimate", help="Show the learner's current estimate z to the participant")] = True,
    llm: opt.Llm = D.llm,
    vlm: opt.Vlm = None,
    base_url: opt.BaseUrl = None,
    cache: opt.Cache = None,
    cache_mode: opt.CacheMode = D.cache_mode,
    executor: opt.Executor = D.executor,
    retriever: opt.Retriever = D.retriever,
    plugin: opt.Plugin = None,
    answer_timeout: Annotated[float, typer.Option("--answer-timeout", min=1.0, help="Seconds to wait for one answer before a session is abandoned")] = 1800.0,
    max_sessions: Annotated[int, typer.Option("--max-sessions", min=1, help="Sessions in progress at once")] = 4,
    max_sessions_per_client: Annotated[int, typer.Option("--max-sessions-per-client", min=1, help="Sessions in progress at once from one client address")] = 2,
    max_new_sessions_per_hour: Annotated[int, typer.Option("--max-new-sessions-per-hour", min=1, help="Sessions one client address may start per hour")] = 30,
    idle_timeout: Annotated[float, typer.Option("--idle-timeout", min=0.1, help="Minutes without a request from a session's page before it is cancelled and its slot freed")] = 3.0,
    max_request_kb: Annotated[int, typer.Option("--max-request-kb", min=1, help="Largest request body in KiB")] = 128,
    events_quota_mb: Annotated[float, typer.Option("--events-quota-mb", min=0.01, help="Largest events.jsonl the browser may fill per session, in MiB")] = 5.0,
) -> None:
    """Serve the study: participants give the preference or stop signal in the browser.

    Each session is saved like a simulated run (summary.json, rounds.jsonl, videos) in OUT/<session-id>/, plus events.jsonl with every UI event. The JSON API is described at /openapi.json.
    """
    import uvicorn
    from rich.console import Console

    from activeintent.intentions.registry import IntentionError
    from activeintent.learners.registry import get_method
    from activeintent.runner import check_options
    from activeintent.suites import resolve as resolve_intention
    from activeintent.web.limits import Limits
    from activeintent.web.server import create_app, runner_builder
    from activeintent.web.session import StudyConfig

    extra = dict(intention_file=intention_file, llm=llm, vlm=vlm, base_url=base_url, cache=cache,
                 cache_mode=cache_mode, executor=executor, retriever=retriever, plugins=list(plugin or []))
    try:
        # options and the hidden intention are checked now so a typo fails before anyone opens the page
        check_options(opt.run_options(method=method, budget=rounds, intention=intention, **extra))
        resolve_intention(intention or (None if intention_file else "color-match"), intention_file)
        signal = get_method(method).signal
    except (ValueError, IntentionError, FileNotFoundError) as err:
        raise typer.BadParameter(str(err)) from None
    config = StudyConfig(method=method, signal=signal, rounds=rounds, intention=intention,
                         show_estimate=show_estimate, out_dir=out, seed=seed,
                         answer_timeout=answer_timeout, max_sessions=max_sessions)
    limits = Limits(max_sessions_per_client=max_sessions_per_client,
                    max_new_sessions_per_hour=max_new_sessions_per_hour, idle_timeout=idle_timeout * 60,
                    max_body_bytes=max_request_kb * 1024, events_quota_bytes=int(events_quota_mb * 2**20))
    app = create_app(config, runner_builder(config, **extra), limits=limits)
    console = Console()
    shown = "localhost" if host in ("127.0.0.1", "::1") else host
    console.print(f"[bold]activeintent study[/]: {method} ({signal} signal), {rounds} rounds; "
                  f"sessions saved in {out}/")
    console.print(f"Open http://{shown}:{port}/ — API schema at /openapi.json. Ctrl-C stops.")
    if host not in ("127.0.0.1", "localhost", "::1"):
        console.print(f"[yellow]Listening on {host}: anyone who can reach this address can take part.[/]")
    uvicorn.run(app, host=host, port=port, log_level="warning")
