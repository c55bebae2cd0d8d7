"""The prior over the goal language fitted to a corpus (goals/prior.py) and `prior fit`."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from activeintent.goals.language import all_clauses, parse_goal
from activeintent.goals.prior import PriorError, choose_alpha, fit, load_prior, read_corpus

TOWER = "form tower:any all:"
RARE = "none all-but:gray side:behind/cyan bowl"


def corpus_goals(n: int = 30):
    keys = [TOWER] * n + ["every all: in-bowl:same", "every class:warm in-bowl:any & every class:cool on-table:"]
    return [parse_goal(k) for k in keys]


def test_the_fitted_prior_is_a_proper_distribution_over_goals():
    prior = fit(corpus_goals(), 0.3)
    p = np.array([2.0 ** prior.clause_log2(c) for c in all_clauses()])
    assert p.sum() == pytest.approx(1.0, abs=1e-9)  # one clause: every clause of the language
    # two and three distinct clauses (any order): n! Π P(c) summed over sets is D_n, which P(z) divides by
    assert prior.distinct(2) == pytest.approx(1 - (p ** 2).sum(), rel=1e-9)
    assert prior.distinct(3) == pytest.approx(1 - 3 * (p ** 2).sum() + 2 * (p ** 3).sum(), rel=1e-9)
    assert sum(prior.p("clauses").values()) == pytest.approx(1) and sum(prior.p("stays").values()) == pytest.approx(1)
    a, b = "every all: in-bowl:same", "form tower:any class:cool"
    assert prior.bits(parse_goal(f"{a} & {b}")) == pytest.approx(prior.bits(parse_goal(f"{b} & {a}")))
    assert prior.bits(parse_goal(f"{a} & {a}")) == math.inf  # a goal names each clause once


def test_the_fitted_weights_move_mass_to_what_people_ask():
    prior = fit(corpus_goals(), 0.3)
    tower, rare = parse_goal(TOWER), parse_goal(RARE)
    assert prior.bits(tower) < tower.bits - 3  # asked 30 times: far cheaper than a uniform choice
    assert prior.bits(rare) > rare.bits  # never asked: dearer
    assert prior.bits(tower) < prior.bits(parse_goal("form row:any all:"))  # equal length, unequal use


def test_smoothing_keeps_every_goal_possible_and_its_strength_is_chosen_by_cross_validation():
    goals = corpus_goals()
    rare = parse_goal(RARE)
    assert math.isfinite(fit(goals, 0.3).bits(rare))  # a choice never seen keeps α of mass
    assert fit(goals, 1e-9).bits(rare) > fit(goals, 0.3).bits(rare) + 20  # without smoothing: next to none
    with pytest.raises(ValueError, match="smoothing"):
        fit(goals, 0.0)
    strong, weak = fit(goals, 100.0), fit(goals, 0.01)
    assert abs(strong.bits(rare) - rare.bits) < abs(weak.bits(rare) - rare.bits)  # α → ∞: uniform choices
    assert choose_alpha(goals) in (0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)


@pytest.mark.parametrize("language,corpus", [(1, "translations.jsonl"), (2, "translations-2.jsonl")])
def test_the_packaged_prior_of_each_language_is_fitted_to_its_committed_corpus(language, corpus):
    from pathlib import Path

    from activeintent.goals.language import speaking

    with speaking(language):
        goals, digest = read_corpus(Path(__file__).resolve().parents[2] / "data" / "requests" / corpus)
        packaged = load_prior("fitted")
        assert packaged.language == language
        assert packaged.corpus == digest and packaged.requests == len(goals)
        refit = fit(goals, packaged.alpha, digest)
    assert refit.to_json() == packaged.to_json()


def test_a_prior_fitted_over_one_language_is_refused_for_a_run_in_another(tmp_path):
    from activeintent.goals.language import speaking

    with speaking(1):
        path = tmp_path / "prior-1.json"
        path.write_text(json.dumps(fit(corpus_goals(), 0.3).to_json()))
        assert load_prior(f"file:{path}").language == 1
    with pytest.raises(PriorError, match="fitted over language 1, the run speaks language 2"):
        load_prior(f"file:{path}", 2)


def test_a_learner_under_the_fitted_prior_reads_its_weights(tmp_path):
    from activeintent.learners.lang.hypotheses import LangSpace

    path = tmp_path / "prior.json"
    path.write_text(json.dumps(fit(corpus_goals(), 0.3).to_json()))
    prior = load_prior(f"file:{path}")
    goals = [parse_goal(k) for k in (TOWER, "form row:any all:", RARE)]
    fitted, length = LangSpace(goals, prior=prior), LangSpace(goals)
    assert [h.bits for h in fitted.hypotheses] == [prior.bits(g) for g in goals]
    assert [h.bits for h in length.hypotheses] == [g.bits for g in goals]
    from activeintent.learners.lang.learner import LangConfig, LangLearner

    learner = LangLearner("stop", rng=0, config=LangConfig(prior=f"file:{path}"), hypotheses=fitted.hypotheses)
    w = learner.weights
    assert w[0] > w[1] > w[2]  # the corpus's goal first: the language's zero-signal guess
    assert learner.bits(goals[2]) == prior.bits(goals[2])


def test_prior_fit_writes_a_prior_or_names_the_bad_line_and_writes_nothing(tmp_path):
    from activeintent.cli import app

    corpus = tmp_path / "corpus.jsonl"
    rows = [{"goal": TOWER}] * 8 + [{"goal": "every all: in-bowl:same"}] * 4 + [{"goal": None}]
    corpus.write_text("".join(json.dumps(r) + "\n" for r in rows))
    out = tmp_path / "prior.json"
    res = CliRunner().invoke(app, ["prior", "fit", "--corpus", str(corpus), "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert load_prior(f"file:{out}").requests == 12
    bad = tmp_path / "bad.jsonl"
    bad.write_text(json.dumps({"goal": TOWER}) + "\n" + json.dumps({"goal": "form tower:zzz all:"}) + "\n")
    out2 = tmp_path / "never.json"
    res = CliRunner().invoke(app, ["prior", "fit", "--corpus", str(bad), "--out", str(out2)])
    assert res.exit_code == 2 and "line 2" in res.output and not out2.exists()
    with pytest.raises(PriorError, match="valid priors"):
        load_prior("clever")


def test_a_fitted_prior_is_refused_for_learners_outside_the_goal_language():
    from activeintent.runner import check_spec
    from activeintent.spec import RunSpec

    with pytest.raises(ValueError, match="--prior: Input should be 'length' or 'uniform'"):
        check_spec(RunSpec.from_options(method="bayes-stop", prior="fitted", llm="none", env="symbolic"))
    check_spec(RunSpec.from_options(method="lang-stop", prior="fitted", llm="none", env="symbolic"))


def test_each_method_takes_its_own_prior_when_none_is_given_and_the_record_keeps_it():
    from activeintent.runner import build_episode, check_spec
    from activeintent.spec import RunSpec

    def prior(**options):
        return check_spec(RunSpec.from_options(llm="none", **options)).learner.settings["prior"]

    assert "prior" not in RunSpec().learner.settings
    assert prior(method="lang-stop") == prior(method="lang-zero-signal") == "fitted"
    assert prior(method="bayes-stop") == "length"
    assert prior(method="lang-stop", prior="length") == "length"
    episode = build_episode(RunSpec.from_options(method="bayes-stop", env="symbolic", llm="none", video="none", budget=1))
    assert episode.extra_config["spec"]["learner"]["settings"]["prior"] == "length"  # what ran, not "the method's own"
