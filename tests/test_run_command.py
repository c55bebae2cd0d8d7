"""`activeintent run` end to end through the CLI: outputs, exit codes, clear errors."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from activeintent.cli import app

runner = CliRunner()


def test_run_writes_summary_rounds_and_gifs(tmp_path):
    out = tmp_path / "run"
    res = runner.invoke(app, ["run", "--method", "bayes-stop", "--intention", "stack", "--budget", "2",
                              "--llm", "none", "--seed", "1", "--test-scenes", "2", "--video", "all",
                              "--out", str(out)])
    assert res.exit_code == 0, res.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["method"] == "bayes-stop" and summary["intention"] == "stack"
    assert summary["signals_used"] == 2 == summary["budget"] and len(summary["success_at"]) == 3
    assert summary["final_goal"] and summary["env"] == "pybullet" and summary["user"]["profile"]["name"] == "human"
    assert len((out / "rounds.jsonl").read_text().splitlines()) == summary["rounds_used"]
    assert list(out.glob("round1_*.gif")) and (out / "final.gif").exists()
    assert f"success@2 = {summary['success']:.2f}" in " ".join(res.output.split())


def test_bad_options_exit_2_with_the_valid_choices(tmp_path):
    res = runner.invoke(app, ["run", "--method", "guess", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "bayes-stop" in res.output and "mllm-llm" in res.output
    res = runner.invoke(app, ["run", "--method", "bayes-stop", "--intention", "stak", "--llm", "none", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "color-match" in res.output
    res = runner.invoke(app, ["run", "--method", "preference", "--llm", "none", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "--llm" in res.output
    res = runner.invoke(app, ["run", "--llm", "chatgpt", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "openai:" in res.output
    res = runner.invoke(app, ["run", "--user", "robot", "--llm", "none", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "human" in res.output and "exact" in res.output
    res = runner.invoke(app, ["run", "--budget", "-1", "--out", str(tmp_path)])
    assert res.exit_code == 2 and "--budget" in res.output


def test_unreachable_model_exits_3(tmp_path):
    res = runner.invoke(app, ["run", "--method", "preference", "--llm", "openai:gpt-x", "--base-url",
                              "http://127.0.0.1:9/v1", "--cache-mode", "off", "--budget", "1", "--env", "symbolic",
                              "--out", str(tmp_path)],
                        env={"OPENAI_API_KEY": "test"})
    assert res.exit_code == 3, res.output
    assert "model" in res.output.lower()


def test_failed_model_calls_show_while_running_and_in_the_summary(tmp_path):
    res = runner.invoke(app, ["run", "--method", "bayes-stop", "--llm", "openai:gpt-x", "--base-url",
                              "http://127.0.0.1:9/v1", "--cache-mode", "off", "--budget", "1", "--env", "symbolic",
                              "--test-scenes", "2", "--test-pool", "0", "--video", "none", "--out", str(tmp_path)],
                        env={"OPENAI_API_KEY": "test"})
    text = " ".join(res.output.split())
    assert "model call failed" in text and "nothing answers at http://127.0.0.1:9/v1" in text
    assert res.exit_code == 3  # the model never answered
    from activeintent.run_command import model_summary

    assert "2 failed" in model_summary("embedded", 5, ["timeout", "timeout"])
    assert model_summary("none", 0, []) == "no model (--llm none)"


def test_run_prints_a_line_per_signal_when_stdout_is_not_a_terminal(tmp_path):
    """CliRunner's stdout is not a terminal, as in `run | cat`: one line per signal, before the table."""
    res = runner.invoke(app, ["run", "--method", "bayes-stop", "--llm", "none", "--env", "symbolic", "--budget", "2",
                              "--test-scenes", "2", "--test-pool", "0", "--video", "none", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    progress = [i for i, line in enumerate(lines) if line.startswith("signal ")]
    assert [lines[i].split(" · ")[0] for i in progress] == ["signal 0/2", "signal 1/2", "signal 2/2"]
    assert "success@1 = " in lines[progress[1]] and "ETA" in lines[progress[1]]
    table = next(i for i, line in enumerate(lines) if "bayes-stop on a hidden intention" in line)
    assert progress[-1] < table


def test_a_bench_record_replays_with_its_seed_and_test_seed(tmp_path):
    """`run --seed S --test-seed T` is the bench's episode: a committed record's success@k comes back
    (T is the record's config.options.test_seed; the top-level test_seed is the test stream's)."""
    results = Path(__file__).resolve().parents[1] / "docs" / "results" / "truth-goals-exact" / "results.jsonl"
    record = next(r for r in map(json.loads, results.read_text().splitlines())
                  if r["method"] == "zero-signal" and r["intention"] == "truth-05")
    options = record["config"]["options"]
    args = ["run", "--method", "zero-signal", "--intention", "truth-05", "--budget", str(record["budget"]),
            "--user", options["user"], "--env", "symbolic", "--llm", "none", "--video", "none",
            "--seed", str(record["seed"])]
    res = runner.invoke(app, [*args, "--test-seed", str(options["test_seed"]), "--out", str(tmp_path / "replay")])
    assert res.exit_code == 0, res.output
    replay = json.loads((tmp_path / "replay" / "summary.json").read_text())
    assert (replay["success_at"], replay["test_scored"]) == (record["success_at"], record["test_scored"])
    res = runner.invoke(app, [*args, "--out", str(tmp_path / "own")])  # the test scenes follow --seed alone
    own = json.loads((tmp_path / "own" / "summary.json").read_text())
    assert (own["success_at"], own["test_scored"]) != (record["success_at"], record["test_scored"])
