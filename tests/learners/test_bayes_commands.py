"""`activeintent hypotheses` prints the size of H, its prior and examples; `bayes-bench` times
the learners in the one episode loop."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from activeintent.cli import app


def test_hypotheses_json():
    result = CliRunner().invoke(app, ["hypotheses", "--json", "--examples", "5"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert 200 <= data["count"] <= data["generated"]
    assert len(data["examples"]) == 5 and all(e["description"].endswith(".") for e in data["examples"])
    priors = [e["prior"] for e in data["examples"]]
    assert priors == sorted(priors, reverse=True)  # examples run from the simplest (most probable) down


def test_hypotheses_table():
    result = CliRunner().invoke(app, ["hypotheses", "--examples", "3"])
    assert result.exit_code == 0, result.output
    assert "distinct hypotheses" in result.output and "description length" in result.output


def test_bayes_bench_times_learners_in_the_episode_loop():
    result = CliRunner().invoke(app, ["bayes-bench", "--json", "--trials", "1"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    for method in ("bayes-preference", "bayes-stop"):
        assert data[method]["signals"] == 5 and 0 < data[method]["median_s"] <= data[method]["max_s"]
