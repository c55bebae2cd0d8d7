"""`activeintent bench` through the CLI: what it runs for --intention-file, and progress lines
on a non-terminal (CliRunner's stdout is not a terminal, as in `bench ... | cat`)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from activeintent.cli import app

ROOT = Path(__file__).resolve().parents[2]
MINE = f"{ROOT}/examples/my_intention.py:RightmostBowl"
TINY = ["--no-oracle", "--env", "symbolic", "--llm", "none", "--budget", "1", "--trials", "1", "--test-scenes", "2",
        "--test-pool", "0"]
runner = CliRunner()


def test_intention_file_alone_runs_just_that_intention_named_by_its_name(tmp_path):
    out = tmp_path / "b"
    res = runner.invoke(app, ["bench", "--methods", "zero-signal,bayes-stop", "--intention-file", MINE, *TINY,
                              "--out", str(out)])
    assert res.exit_code == 0, res.output
    records = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert {r["intention"] for r in records} == {MINE} and len(records) == 2
    assert json.loads((out / "bench.json").read_text())["intentions"] == []
    report = (out / "report.md").read_text()
    assert "| rightmost-bowl |" in report and "RightmostBowl |" not in report
    # one flushed line per episode: done/total, method, intention, then elapsed and ETA
    lines = [line for line in res.stdout.splitlines() if line.startswith(("1/2 · ", "2/2 · "))]
    assert [line.split(" · ")[:3] for line in lines] == [["1/2", "zero-signal", "rightmost-bowl"],
                                                        ["2/2", "bayes-stop", "rightmost-bowl"]]
    assert all("elapsed " in line and "ETA " in line for line in lines)
    assert res.stdout.index("2/2 · ") < res.stdout.index("# activeintent benchmark")


def test_a_named_suite_still_runs_beside_an_intention_file(tmp_path, monkeypatch):
    import activeintent.cli.bench as bench_command
    from activeintent.suites import suite

    asked = []
    monkeypatch.setattr(bench_command, "run_bench", lambda options, out, *hooks: asked.append(options) or [])
    res = runner.invoke(app, ["bench", "--methods", "zero-signal", "--suite", "paper", "--intention-file", MINE,
                              *TINY, "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert asked[0].intentions == suite("paper") and asked[0].intention_files == [MINE]


def test_the_file_intention_name_in_intentions_says_what_to_do(tmp_path):
    res = runner.invoke(app, ["bench", "--methods", "zero-signal", "--intention-file", MINE,
                              "--intentions", "rightmost-bowl", *TINY, "--out", str(tmp_path)])
    assert res.exit_code == 2
    assert "--intention-file" in res.output and "drop it from --intentions" in " ".join(res.output.split())


def test_perf_bench_prints_a_line_per_episode_on_stderr_and_keeps_stdout_json():
    res = runner.invoke(app, ["perf-bench", "--json", "--episodes", "1", "--envs", "symbolic", "--budget", "1"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["settings"]["symbolic"]["signals"] == 1
    line = next(line for line in res.stderr.splitlines() if line.startswith("1/1 · "))
    assert line.split(" · ")[:4] == ["1/1", "bayes-stop", "symbolic", "color-match"] and "ETA" in line


def test_perf_bench_splits_an_episode_into_per_signal_work_and_the_rest():
    """outside_signals_s: the episode less the learner's per-signal work; for a method that
    asks nothing, the whole episode (and no per-signal figures, not a crash)."""
    res = runner.invoke(app, ["perf-bench", "--json", "--episodes", "1", "--envs", "symbolic", "--budget", "2"])
    got = json.loads(res.stdout)["settings"]["symbolic"]
    assert 0 < got["outside_signals_s_median"] < got["episode_s_median"]
    assert got["outside_signals_s_median"] + 2 * got["learner_s_per_signal_median"] == pytest.approx(
        got["episode_s_median"], abs=0.5 * got["episode_s_median"])
    res = runner.invoke(app, ["perf-bench", "--json", "--method", "zero-signal", "--episodes", "1", "--envs", "symbolic",
                              "--budget", "2"])
    assert res.exit_code == 0, res.output
    got = json.loads(res.stdout)["settings"]["symbolic"]
    assert got["outside_signals_s_median"] == got["episode_s_median"] and got["learner_s_per_signal_median"] is None


def test_the_report_carries_the_oracle_row_measured_by_coverage(tmp_path):
    from activeintent.bench.coverage import cached_coverage
    from activeintent.suites import resolve

    out = tmp_path / "b"
    tiny = [a for a in TINY if a != "--no-oracle"]
    res = runner.invoke(app, ["bench", "--methods", "zero-signal", "--intentions", "stack", *tiny, "--out", str(out)])
    assert res.exit_code == 0, res.output
    row = next(line for line in (out / "report.md").read_text().splitlines() if line.startswith("| *oracle*"))
    want = cached_coverage(resolve("stack"))["success"]  # the cache the bench filled
    assert f"| {want:.2f} |" in row and f"**{want:.2f}**" in row
    out2 = tmp_path / "c"
    res = runner.invoke(app, ["bench", "--methods", "zero-signal", "--intentions", "stack", *TINY, "--out", str(out2)])
    assert "not measured" in next(line for line in (out2 / "report.md").read_text().splitlines()
                                  if line.startswith("| *oracle*"))
