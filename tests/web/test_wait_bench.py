"""web-bench measures the real app's wait between rounds (figures are printed, not asserted)."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from activeintent.cli import app


def test_web_bench_times_every_wait_of_a_real_session():
    res = CliRunner().invoke(app, ["web-bench", "--rounds", "3", "--sessions", "1", "--video-size", "64", "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout.strip().splitlines()[-1])
    session = out["per_session"][0]
    assert out["waits"] == len(session["waits_s"]) == 2  # rounds − 1 answers lead to another round
    assert all(w > 0 for w in session["waits_s"]) and session["first_round_s"] > 0
    assert out["p50_s"] <= out["p90_s"] and out["video_px"] == [64, 64] and out["target_p90_s"] == 3.0


def test_web_bench_names_an_unknown_method():
    res = CliRunner().invoke(app, ["web-bench", "--method", "bayes-stp", "--rounds", "2", "--sessions", "1"])
    assert res.exit_code != 0 and "bayes-stop" in res.output
