"""Spec strings, shared model options, usage accounting."""

from __future__ import annotations

import pytest
from fault_server import FaultServer, Ok

from activeintent.llm.accounting import CallRecord, Usage
from activeintent.llm.base import Message
from activeintent.llm.models import Models
from activeintent.llm.registry import load_model, parse_spec
from activeintent.runner import RunSpec, check_spec


@pytest.mark.parametrize(
    ("spec", "kind", "target"),
    [
        ("embedded", "embedded", None),
        ("gguf:/models/x.gguf", "gguf", "/models/x.gguf"),
        ("openai:gpt-4o-mini", "openai", "gpt-4o-mini"),
        ("openai:qwen2.5:7b", "openai", "qwen2.5:7b"),  # Ollama names contain colons
    ],
)
def test_valid_specs(spec, kind, target):
    parsed = parse_spec(spec)
    assert (parsed.kind, parsed.target) == (kind, target)
    assert str(parsed) == spec


@pytest.mark.parametrize("spec", ["", "gpt-4", "openai:", "gguf:", "hf:gemma", "Embedded"])
def test_bad_spec_lists_valid_forms(spec):
    with pytest.raises(ValueError) as info:
        parse_spec(spec)
    message = str(info.value)
    assert "embedded" in message and "gguf:/path/model.gguf" in message and "openai:<model-name>" in message


def test_run_options_refuse_bad_model_options_clearly():
    with pytest.raises(ValueError, match="openai:<model-name>"):
        check_spec(RunSpec.from_options(method="preference", llm="gpt4"))
    with pytest.raises(ValueError, match="openai:<model-name>"):
        check_spec(RunSpec.from_options(method="bayes-stop", llm="none", vlm="gpt4"))
    with pytest.raises(ValueError, match="--cache-mode: .*record"):
        RunSpec.from_options(cache_mode="replay-only")


def test_a_runs_models_share_the_cache_and_count_usage_together(tmp_path):
    with FaultServer() as server:
        server.default = Ok("fine")
        models = Models(RunSpec.from_options(llm="openai:text-model", vlm="openai:vision-model",
                                             base_url=server.base_url, cache=str(tmp_path / "c.sqlite")).models)
        assert models.llm is not models.vlm
        user = [Message(role="user", content="hi")]
        models.llm.chat(user)
        models.vlm.chat(user)
        models.vlm.chat(user)  # cache hit
        assert [r["model"] for r in server.requests] == ["text-model", "vision-model"]
        assert models.usage()[0] == 3  # calls, over both models

        same = Models(RunSpec.from_options(llm="openai:m", vlm="openai:m", base_url=server.base_url, cache_mode="off").models)
        assert same.llm is same.vlm


def test_load_model_openai(tmp_path):
    with FaultServer() as server:
        server.default = Ok("pong")
        model = load_model("openai:m", base_url=server.base_url, cache_path=tmp_path / "c.sqlite")
        assert model.chat([Message(role="user", content="ping")]) == "pong"
        assert model.name == "openai:m"
        replay = load_model("openai:m", base_url=server.base_url, cache=str(tmp_path / "c.sqlite"),
                            cache_mode="replay")
        assert replay.chat([Message(role="user", content="ping")]) == "pong"
        assert len(server.requests) == 1
        with pytest.raises(ValueError, match="record, replay, off"):
            load_model("openai:m", base_url=server.base_url, cache_mode="sometimes")


def test_usage_snapshot_diff_gives_per_episode_totals():
    usage = Usage()
    usage.record(CallRecord(backend="b", model="m", kind="chat", prompt_tokens=100,
                            completion_tokens=10, latency_s=0.5))
    start = usage.snapshot()
    usage.record(CallRecord(backend="b", model="m", kind="structured", prompt_tokens=600,
                            completion_tokens=60, latency_s=1.5, attempts=3))
    usage.record(CallRecord(backend="b", model="m", kind="chat", cache_hit=True))
    episode = usage.diff(start)
    assert (episode.calls, episode.prompt_tokens, episode.completion_tokens) == (2, 600, 60)
    assert (episode.cache_hits, episode.cache_misses, episode.retries) == (1, 1, 2)
    assert episode.latency_s == pytest.approx(1.5)
    assert usage.snapshot().calls == 3


def test_replay_needs_no_api_key(tmp_path, monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    monkeypatch.delenv("OPENAI_BASE_URL", raising=False)
    path = tmp_path / "c.sqlite"
    with FaultServer() as server:
        server.default = Ok("recorded")
        recorder = load_model("openai:gpt-x", base_url=server.base_url, cache_path=path)
        assert recorder.chat([Message(role="user", content="q")]) == "recorded"
    # The server is gone and there is no key: the cache answers (its keys name the server's URL).
    offline = load_model("openai:gpt-x", base_url=server.base_url, cache_path=path, cache_mode="replay")
    assert offline.chat([Message(role="user", content="q")]) == "recorded"
