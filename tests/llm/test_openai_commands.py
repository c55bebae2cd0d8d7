"""`run` and `bench` against a local model server whose 200s are malformed: the run exits 3
naming the model and writes summary.json; the bench records an error episode that
--retry-errors runs again."""

from __future__ import annotations

import json

import pytest
from fault_server import FaultServer, Ok, Raw
from typer.testing import CliRunner

from activeintent.cli import app

cli = CliRunner()
BAD = {
    "not UTF-8": '{"choices": [{"message": {"content": "caf\xe9"}}]}'.encode("latin-1"),
    "choices a string": b'{"choices": "nope"}',
    "NaN usage": b'{"choices": [{"message": {"content": "{}"}}], "usage": {"prompt_tokens": NaN}}',
    # issue 58, L2: a RecursionError escaped the parser (exit 1, a traceback, no summary.json)
    "nested 100,000 deep": b'{"choices": ' + b"[" * 100_000 + b"]" * 100_000 + b"}",
}
DEEP_CONTENT = '{"a": ' + "[" * 100_000 + "]" * 100_000 + "}"  # a valid chat completion, too deep an answer
# Small limits through the environment, as a user would set them; retries stop at the deadline.
ENV = {"OPENAI_API_KEY": "test", "ACTIVEINTENT_MODEL_DEADLINE_S": "2"}
EPISODE = ["--method", "preference", "--budget", "1", "--env", "symbolic", "--test-scenes", "2",
           "--test-pool", "0", "--cache-mode", "off"]


@pytest.mark.parametrize("case", list(BAD))
def test_run_exits_3_naming_the_model_and_writes_the_summary(tmp_path, case):
    with FaultServer() as server:
        server.default = Raw(BAD[case])
        res = cli.invoke(app, ["run", *EPISODE, "--llm", "openai:fake-model", "--base-url", server.base_url,
                               "--video", "none", "--out", str(tmp_path)], env=ENV)
    text = " ".join(res.output.split())
    assert res.exit_code == 3, res.output
    assert "openai:fake-model" in text and "malformed" in text
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "openai:fake-model" in summary["error"] and summary["success"] is None


def test_a_too_deep_answer_is_a_model_error_in_run_and_bench(tmp_path):
    """L2: valid content nested 100,000 deep used to raise RecursionError out of
    parse_structured: `run` exited 1 with a traceback and wrote no summary.json."""
    with FaultServer() as server:
        server.default = Ok(DEEP_CONTENT)
        res = cli.invoke(app, ["run", *EPISODE, "--llm", "openai:fake-model", "--base-url", server.base_url,
                               "--video", "none", "--out", str(tmp_path / "run")], env=ENV)
        assert res.exit_code == 3, res.output
        assert "nest 100001 deep" in " ".join(res.output.split())
        summary = json.loads((tmp_path / "run" / "summary.json").read_text())
        assert "openai:fake-model" in summary["error"] and summary["success"] is None
        res = cli.invoke(app, ["bench", "--no-oracle", "--methods", "preference", "--intentions", "color-match",
                               "--trials", "1", "--budget", "1", "--env", "symbolic", "--test-scenes", "2",
                               "--test-pool", "0", "--cache-mode", "off", "--llm", "openai:fake-model",
                               "--base-url", server.base_url, "--out", str(tmp_path / "bench")], env=ENV)
    assert res.exit_code == 0, res.output
    (record,) = [json.loads(x) for x in (tmp_path / "bench" / "results.jsonl").read_text().splitlines()]
    assert "nest 100001 deep" in record["error"] and record["success"] is None


def test_bench_records_a_model_failure_as_an_error_that_retry_errors_reruns(tmp_path):
    bench = ["bench", "--no-oracle", "--methods", "preference", "--intentions", "color-match", "--trials", "1", "--budget", "1",
             "--env", "symbolic", "--test-scenes", "2", "--test-pool", "0", "--cache-mode", "off",
             "--llm", "openai:fake-model", "--out", str(tmp_path)]
    with FaultServer() as server:
        server.default = Raw(BAD["not UTF-8"])
        first = cli.invoke(app, [*bench, "--base-url", server.base_url], env=ENV)
        assert first.exit_code == 0, first.output
        (record,) = [json.loads(x) for x in (tmp_path / "results.jsonl").read_text().splitlines()]
        assert "openai:fake-model" in record["error"] and "not UTF-8" in record["error"]
        asked = len(server.requests)
        again = cli.invoke(app, [*bench, "--base-url", server.base_url, "--retry-errors"], env=ENV)
        assert again.exit_code == 0, again.output
        assert len(server.requests) > asked  # the episode ran again
    lines = (tmp_path / "results.jsonl").read_text().splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["error"]
