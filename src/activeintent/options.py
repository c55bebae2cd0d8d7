"""Command-line options shared by `run`, `bench` and `serve` (typer annotations)."""

from __future__ import annotations

from typing import Annotated

import typer

from activeintent.runner import UserOptions

Llm = Annotated[str, typer.Option("--llm", help="LLM spec: embedded | gguf:/path.gguf | openai:<model> | none (Bayesian methods only)")]
Vlm = Annotated[str | None, typer.Option("--vlm", help="Multimodal model spec for the retriever (default: the LLM)")]
BaseUrl = Annotated[str | None, typer.Option("--base-url", envvar="OPENAI_BASE_URL", help="OpenAI-compatible endpoint")]
Cache = Annotated[str | None, typer.Option("--cache", help="Response cache file (SQLite); default ~/.cache/activeintent")]
CacheMode = Annotated[str, typer.Option("--cache-mode", help="record | replay | off")]
Executor = Annotated[str, typer.Option("--executor", help="y → plan: parse | plan | cap")]
Retriever = Annotated[str, typer.Option("--retriever", help="r from a stop: symbolic | vision")]
Intention = Annotated[str | None, typer.Option("--intention", help="Hidden intention (see `activeintent intentions`)")]
IntentionFile = Annotated[str | None, typer.Option("--intention-file", help="Your own intention: path.py:NAME")]
Rounds = Annotated[int, typer.Option("--rounds", min=1, help="K: feedback signals per episode")]
Seed = Annotated[int, typer.Option("--seed", help="Seed of every random choice")]
UserBeta = Annotated[float, typer.Option("--user-beta", help="Preference-user rationality β (inf = exact user)")]
ReactionDelay = Annotated[str, typer.Option("--reaction-delay", help="Stop-user reaction delay MEAN,SD in seconds")]
FalseStop = Annotated[float, typer.Option("--false-stop", min=0.0, max=1.0, help="P(stop although nothing is wrong)")]
MissedStop = Annotated[float, typer.Option("--missed-stop", min=0.0, max=1.0, help="P(no stop although something is wrong)")]


def user_options(beta: float, reaction_delay: str, false_stop: float, missed_stop: float) -> UserOptions:
    try:
        mean, sd = (float(v) for v in reaction_delay.split(","))
    except ValueError:
        raise typer.BadParameter(f"--reaction-delay takes MEAN,SD in seconds, e.g. 0.5,0.15; got {reaction_delay!r}") from None
    if mean < 0 or sd < 0:
        raise typer.BadParameter("--reaction-delay MEAN and SD must be ≥ 0")
    return UserOptions(beta=beta, reaction_delay_mean=mean, reaction_delay_sd=sd,
                       false_stop=false_stop, missed_stop=missed_stop)
