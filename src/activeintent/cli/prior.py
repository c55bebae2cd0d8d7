"""`activeintent prior fit`: a prior over the goal language fitted to a corpus of requests."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Annotated

import typer

from activeintent.goals.prior import PriorError, choose_alpha, fit, nested_cv, read_corpus


def register(app: typer.Typer) -> None:
    prior = typer.Typer(help="Priors over the goal language (lang-*): fit one to your population's requests.",
                        no_args_is_help=True)
    prior.command(name="fit")(prior_fit)
    app.add_typer(prior, name="prior")


def prior_fit(
    corpus: Annotated[Path, typer.Option("--corpus", help="JSON lines with a \"goal\" key per request (a goal of "
                                         "the language, or null when it cannot say it), e.g. data/requests/"
                                         "translations.jsonl or `study-export --corpus`'s file")],
    out: Annotated[Path, typer.Option("--out", help="Where to write the prior (JSON); use it as --prior file:OUT")],
    folds: Annotated[int, typer.Option("--folds", min=2, max=20, help="Cross-validation folds for the smoothing strength")] = 5,
) -> None:
    """Count each choice of the grammar in the corpus's goals, choose the Dirichlet smoothing
    strength by cross-validation, write the prior, and report held-out bits per request against
    the length prior (nested cross-validation)."""
    try:
        goals, digest = read_corpus(corpus)
    except PriorError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from None
    if len(goals) < 2 * folds:
        typer.echo(f"error: {corpus} has {len(goals)} translated requests; --folds {folds} needs at least "
                   f"{2 * folds}", err=True)
        raise typer.Exit(2)
    alpha = choose_alpha(goals, k=folds)
    prior = fit(goals, alpha, digest)
    cv = nested_cv(goals, k=folds)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")  # written whole or not at all
    tmp.write_text(json.dumps({**prior.to_json(), "cross_validation": cv}, indent=1) + "\n")
    os.replace(tmp, out)
    typer.echo(f"{len(goals)} translated requests (sha256 {digest[:12]}), smoothing α = {alpha}; held-out bits "
               f"per request ({folds}-fold nested cross-validation): fitted {cv['fitted_bits']}, length "
               f"{cv['length_bits']} (saves {cv['saved_bits']} [{cv['saved_bits_95'][0]}, {cv['saved_bits_95'][1]}])")
    typer.echo(f"wrote {out}; use it with --prior file:{out}")
