"""`activeintent web-bench`: the wait between rounds of the web study (measured in
web/wait_bench.py)."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from activeintent.cli import options as opt
from activeintent.web.basics import VIDEO_SIZE_TEXT
from activeintent.web.wait_bench import measure_waits


def register(app: typer.Typer) -> None:
    app.command(name="web-bench")(web_bench)


def web_bench(
    method: Annotated[str, typer.Option("--method", help="A method of the web study (see `activeintent methods`)")] = "bayes-stop",
    rounds: Annotated[int, typer.Option("--rounds", min=2, max=30, help="Rounds of the session (waits: rounds − 1)")] = 5,
    video_size: opt.VideoSize = VIDEO_SIZE_TEXT,
    sessions: Annotated[int, typer.Option("--sessions", min=1, max=20, help="Sessions, one after another (seeds 0, 1, …)")] = 2,
    intention: Annotated[str | None, typer.Option("--intention", help="An assigned rule (default: free rule)")] = None,
    seed: Annotated[int, typer.Option("--seed", min=0, help="Seed of the sessions")] = 0,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON only")] = False,
) -> None:
    """Measure the wait between rounds of the web study (p50 / p90; target p90 ≤ 3 s at 480 px)."""
    from rich.console import Console

    console = Console(stderr=as_json)
    size = tuple(video_size)  # parsed by the option
    px = f"{size[0]}×{size[1]} px"
    results = []
    with tempfile.TemporaryDirectory(prefix="web-bench-") as tmp:
        for n in range(sessions):
            console.print(f"session {n + 1}/{sessions}: {method}, {rounds} rounds, {px} …")
            try:
                results.append(measure_waits(method, rounds, size, seed + n, Path(tmp) / f"s{n}", intention))
            except (ValueError, RuntimeError, TimeoutError) as err:
                console.print(f"[red]error:[/red] {err}")
                raise typer.Exit(2) from None
    waits = np.array([w for r in results for w in r["waits_s"]])
    summary = {"method": method, "video_px": list(size), "sessions": sessions, "waits": len(waits),
               "p50_s": round(float(np.percentile(waits, 50)), 2), "p90_s": round(float(np.percentile(waits, 90)), 2),
               "first_round_s": [r["first_round_s"] for r in results], "target_p90_s": 3.0,
               "ahead_min_s": min(a for r in results for a in r["ahead_s"]), "per_session": results}
    if as_json:
        print(json.dumps(summary))
        return
    console.print(f"between-round wait, {method} at {px}: p50 {summary['p50_s']:.2f} s, "
                  f"p90 {summary['p90_s']:.2f} s over {len(waits)} waits (target p90 ≤ 3 s); first round "
                  f"{', '.join(f'{x:.1f}' for x in summary['first_round_s'])} s (simulator start included); "
                  f"videos complete ≥ {summary['ahead_min_s']:.1f} s before their playback ends")
