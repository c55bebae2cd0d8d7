"""`activeintent perf-bench`: fixed episodes, time per phase, so every change can be judged.

Phases come from the episode's own clock (``EpisodeResult.time_split``): env (physics or the
symbolic model), learner (its own work, model calls included), executor, user, scoring (the
hidden intention judged on test scenes), video; ``model_s`` is the part of learner and
executor spent in model calls.
"""

from __future__ import annotations

import json
import statistics
import time
from typing import Annotated

import typer

from activeintent.progress_lines import Eta, print_line
from activeintent.runner import RunSpec, build_episode


def register(app: typer.Typer) -> None:
    app.command(name="perf-bench")(perf_bench)


def perf_bench(
    as_json: Annotated[bool, typer.Option("--json", help="print JSON")] = False,
    episodes: Annotated[int, typer.Option(min=1, help="episodes per setting")] = 3,
    method: Annotated[str, typer.Option("--method")] = "bayes-stop",
    envs: Annotated[str, typer.Option("--envs", help="comma-separated envs")] = "symbolic,pybullet",
    intentions: Annotated[str, typer.Option("--intentions", help="comma-separated hidden intentions")] = "color-match",
    budget: Annotated[int, typer.Option(min=1, help="signals per episode")] = 5,
) -> None:
    """Time per phase and per episode of fixed `run`-like episodes (no video, no model), the
    learner's time per signal (choosing the query, reading the answer; scoring excluded), and
    the time of an episode outside that per-signal work (scoring, env, user, records)."""
    class RoundTimes:
        def __init__(self) -> None:
            self.learner_s: list[float] = []

        def answered(self, log) -> None:
            self.learner_s.append(log.timing.get("learner_s", 0.0))

    from rich.console import Console

    names = [n.strip() for n in intentions.split(",") if n.strip()]
    env_names = [e.strip() for e in envs.split(",") if e.strip()]
    # One flushed line per episode on stderr (stdout stays the JSON), so a log shows it is alive.
    log = Console(stderr=True)
    eta = Eta(len(env_names) * len(names) * episodes)
    done = 0
    out: dict = {"method": method, "episodes": episodes, "intentions": names, "budget": budget, "settings": {}}
    for env in env_names:
        walls, phases, rounds, outside = [], [], RoundTimes(), []
        for name in names:
            for seed in range(episodes):
                signals_before = len(rounds.learner_s)
                options = RunSpec.from_options(method=method, intention=name, env=env, llm="none", video="none", seed=seed,
                                     budget=budget)
                start = time.perf_counter()
                episode = build_episode(options)
                episode.observers.append(rounds)
                try:
                    result = episode.run()
                finally:
                    episode.env.close()
                walls.append(time.perf_counter() - start)
                phases.append(result.time_split)
                # everything but the learner's own per-signal work: scoring, env, user, records
                outside.append(walls[-1] - sum(rounds.learner_s[signals_before:]))
                done += 1
                print_line(log, f"{done}/{eta.total} · {method} · {env} · {name} · seed {seed} · "
                           f"{walls[-1]:.1f} s · {eta.text(done)}")
        keys = phases[0].keys()
        out["settings"][env] = {
            "episode_s_median": round(statistics.median(walls), 3),
            "episode_s_max": round(max(walls), 3),
            "phase_s_mean": {k: round(statistics.fmean(p[k] for p in phases), 3) for k in keys},
            "outside_signals_s_median": round(statistics.median(outside), 3),
            # None for a method that asks nothing (zero-signal)
            "learner_s_per_signal_median": round(statistics.median(rounds.learner_s), 3) if rounds.learner_s else None,
            "learner_s_per_signal_p90": (round(sorted(rounds.learner_s)[int(0.9 * (len(rounds.learner_s) - 1))], 3)
                                         if rounds.learner_s else None),
            "signals": len(rounds.learner_s),
        }
    if as_json:
        typer.echo(json.dumps(out, indent=2))
        return
    Console().print_json(json.dumps(out))
