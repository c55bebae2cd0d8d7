"""`activeintent run` end to end through the CLI: outputs, exit codes, clear errors."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from activeintent.bench.legacy import migrated
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
    from activeintent.cli.run import model_summary

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
    (T is the record's config.spec.protocol.test_seed; the top-level test_seed is the test stream's)."""
    results = Path(__file__).resolve().parents[1] / "docs" / "results" / "truth-goals-exact" / "results.jsonl"
    record = next(r for r in map(json.loads, results.read_text().splitlines())
                  if r["method"] == "zero-signal" and r["intention"] == "truth-05")
    spec = migrated(record)["config"]["spec"]
    options = {"user": spec["user"]["preset"], "test_seed": spec["protocol"]["test_seed"]}
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


def _round_log(round_: int, z: str, signals: int, goal: str = "put the red block in the red bowl"):
    from types import SimpleNamespace

    return SimpleNamespace(round=round_, z=z, counted=True, signals_used=signals, labels=["y"], goals=[goal],
                           retrieved=None, calls=[],
                           answer={"signal": "stop", "stop_time": 1.5, "tick": 3, "frame": 15, "new_scene": False})


def _table_rows(live) -> list[list[str]]:
    return [[str(c._cells[i]) for c in live.table.columns] for i in range(live.table.row_count)]


def test_table_row_k_shows_round_k_answer_and_the_estimate_after_it():
    """Row k: round k's answer beside the estimate after it (the next round's z, or the final
    one), which is what success@k scores; and every round that happened has its row, scored or
    not (slow learners are scored at k = K only)."""
    from types import SimpleNamespace

    from activeintent.cli.run import LiveTable, plain_console

    final = SimpleNamespace(final_z="z after 2", final_goal="g", final_scene=0, success=1.0)
    live = LiveTable(plain_console(), "bayes-stop", 2, 0, lines=False)
    live.answered(_round_log(1, "prior z", 1))
    live.scored(1, 0.5)
    live.answered(_round_log(2, "z after 1", 2))
    live.scored(2, 1.0)
    live.final(final)
    rows = _table_rows(live)
    assert [r[0] for r in rows] == ["1", "2", "final"]
    z, rate = live.table.columns.index(next(c for c in live.table.columns if c.header.startswith("z"))), -1
    assert (rows[0][z], rows[0][rate]) == ("z after 1", "0.50")
    assert (rows[1][z], rows[1][rate]) == ("z after 2", "1.00")
    assert rows[2][1].startswith("test scene 1: ")  # scenes are numbered from 1 where printed
    # no scoring between rounds (a model-driven learner): the rounds still show
    slow = LiveTable(plain_console(), "preference", 3, 0, lines=False)
    for k in (1, 2, 3):
        slow.answered(_round_log(k, f"z{k}", k))
    slow.flush()  # e.g. a model error after round 3
    assert [r[0] for r in _table_rows(slow)] == ["1", "2", "3"]


def test_user_strings_print_without_markup_and_messages_whole():
    import io

    from activeintent.cli.run import model_summary, plain_console

    console = plain_console()
    console.file = io.StringIO()
    long = "the server said: " + "word " * 60 + "END"
    console.print(f"{model_summary('openai:x', 3, [long])} · done", soft_wrap=True)
    text = console.file.getvalue()
    assert "openai:x: 3 calls" in text and "❌" not in text  # ":x:" is no emoji here
    assert long in text  # the whole failure message, not cut mid-word


def test_piped_tables_are_wide_and_video_final_says_why_there_is_no_gif(tmp_path):
    res = runner.invoke(app, ["run", "--method", "lang-stop", "--llm", "none", "--env", "symbolic", "--budget", "1",
                              "--test-scenes", "2", "--test-pool", "0", "--video", "final", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert not (tmp_path / "final.gif").exists()
    assert "no final.gif: the symbolic env draws no pictures" in res.output
    lines = res.output.splitlines()
    header = next(line for line in lines if "z (estimate after the answer)" in line)
    assert len(header) > 80  # not wrapped to 80 columns when piped
