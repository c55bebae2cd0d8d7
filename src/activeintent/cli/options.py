"""Command-line options shared by `run`, `bench` and `serve`: declared once here, defaults
read from :class:`activeintent.spec.RunSpec` (``D``: its defaults under the options' names), so
nothing is typed twice."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Annotated

import typer

from activeintent.spec import RunSpec
from activeintent.web.basics import parse_video_size

D = SimpleNamespace(**RunSpec().options())  # the defaults, by option name

Method = Annotated[str, typer.Option("--method", help="Learner (see `activeintent methods`)")]
Intention = Annotated[str | None, typer.Option("--intention", help="Hidden intention (see `activeintent intentions`)")]
IntentionFile = Annotated[str | None, typer.Option("--intention-file", help="Your own intention: path.py:NAME")]
Plugin = Annotated[list[str] | None, typer.Option("--plugin", help="Python file registering signals, methods, envs… (repeatable)")]
Budget = Annotated[int, typer.Option("--budget", min=0, max=100, help="K: signals the user gives; every answer counts")]
Seed = Annotated[int, typer.Option("--seed", min=0, help="Seed of every random choice")]
TestSeed = Annotated[int | None, typer.Option("--test-seed", min=0, help="Seed of the test scenes (default: from --seed); a bench record's config.options.test_seed replays its episode")]
TestScenes = Annotated[int, typer.Option("--test-scenes", min=1, max=200, help="Test scenes scored after every signal")]
TestPool = Annotated[int, typer.Option("--test-pool", min=0, max=1000, help="More test scenes, scored after the last signal (k = K)")]
Env = Annotated[str, typer.Option("--env", help="Where plans run: pybullet | symbolic")]
User = Annotated[str, typer.Option("--user", help="Simulated-user preset: human | paper | exact (see docs/protocol.md)")]
NewScene = Annotated[str, typer.Option("--new-scene", help="counted (every answer is a signal) | free (old rule, ≤3 uncounted) | off")]
Prior = Annotated[str | None, typer.Option("--prior", help="Bayesian prior: length (description length) | uniform | fitted (lang-*: fitted to data/requests) | file:PATH (lang-*: written by `prior fit`); default: the method's own (lang-*: fitted, the others: length)")]
Scenes = Annotated[str, typer.Option("--scenes", help="bayes-* and lang-*: scenes to ask in: sampled | belief (those the belief expects to show its goals) | a plug-in's (SCENE_DESIGNS)")]
Llm = Annotated[str, typer.Option("--llm", help="LLM: embedded | gguf:/path.gguf | openai:<model> | none (Bayesian methods and baselines)")]
Vlm = Annotated[str | None, typer.Option("--vlm", help="Multimodal model spec for the retriever (default: the LLM)")]
BaseUrl = Annotated[str | None, typer.Option("--base-url", envvar="OPENAI_BASE_URL", help="OpenAI-compatible endpoint")]
Cache = Annotated[str | None, typer.Option("--cache", help="Response cache file (SQLite); default ~/.cache/activeintent")]
CacheMode = Annotated[str, typer.Option("--cache-mode", help="record | replay | off")]
Executor = Annotated[str, typer.Option("--executor", help="y → plan: parse | plan | cap")]
UnsafeNoIsolation = Annotated[bool, typer.Option("--unsafe-no-isolation", envvar="ACTIVEINTENT_UNSAFE_NO_ISOLATION", help="Run model-written code (--executor cap, proposed predicates) even without the bubblewrap sandbox (docs/security.md)")]
Retriever = Annotated[str, typer.Option("--retriever", help="r from a stop: symbolic | vision")]
Epsilon = Annotated[float, typer.Option("--epsilon", min=0.0, help="ε: seconds before the stop for image I_b")]
EarlyThreshold = Annotated[float, typer.Option("--early-threshold", min=0.0, help="eq. 3: a stop earlier than this (s) shows no I_b")]
Variant = Annotated[str, typer.Option("--variant", help="Paper methods: faithful (free text, reasoning, memory, T = 1) | structured")]
Video = Annotated[str, typer.Option("--video", help="GIFs written: none | final | all")]
Out = Annotated[Path | None, typer.Option("--out", help="Output folder")]


def check_only() -> bool:
    """ACTIVEINTENT_CHECK_ONLY=1: commands validate their options and inputs, then stop before
    the work (the docs test runs every documented command this way)."""
    import os

    return os.environ.get("ACTIVEINTENT_CHECK_ONLY") == "1"


def run_spec(**values) -> RunSpec:
    """The run's spec from CLI values (None: the default); a bad value becomes a message naming
    the option."""
    values = {k: v for k, v in values.items() if v is not None or k in ("intention", "intention_file", "vlm")}
    values["plugins"] = list(values.get("plugins") or [])
    return RunSpec.from_options(**values)


def _video_size(text: str) -> tuple[int, int]:
    try:
        return parse_video_size(text)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


VideoSize = Annotated[str, typer.Option(
    "--video-size", callback=_video_size,
    help="Videos' WIDTHxHEIGHT in pixels (64-2048 each), or one number for a square; at the default every "
    "block is at least 40 px wide, larger takes longer to render before each round")]
