"""Response cache: record, replay, off; keys; several writer processes."""

from __future__ import annotations

import multiprocessing as mp

import numpy as np
import pytest
from fault_server import FaultServer, Ok
from pydantic import BaseModel

from activeintent.llm.backend import BackendModel, ChatRequest, Completion
from activeintent.llm.base import CacheMissError, ImagePart, Message, TextPart
from activeintent.llm.cache import ResponseCache
from activeintent.llm.openai_compat import OpenAIBackend
from activeintent.llm.retry import RetryPolicy
from activeintent.llm.scripted import ScriptedModel


class Choice(BaseModel):
    better: int


USER = [Message(role="user", content="Which goal was better, 1 or 2?")]


def test_replay_after_record_gives_identical_answers_without_model_calls(tmp_path):
    path = tmp_path / "responses.sqlite"
    recorder = ScriptedModel(["free text answer", {"better": 2}], cache=ResponseCache(path))
    first = (recorder.chat(USER), recorder.structured(USER, Choice, prompt_version="eq3-v1"))
    assert len(recorder.calls) == 2

    replayer = ScriptedModel([], cache=ResponseCache(path, "replay"))  # would fail if called
    second = (replayer.chat(USER), replayer.structured(USER, Choice, prompt_version="eq3-v1"))
    assert second == first == ("free text answer", Choice(better=2))
    assert replayer.calls == []
    totals = replayer.usage.snapshot()
    assert (totals.calls, totals.cache_hits, totals.cache_misses) == (2, 2, 0)


def test_record_mode_reads_its_own_entries(tmp_path):
    model = ScriptedModel(["once"], cache=ResponseCache(tmp_path / "c.sqlite"))
    assert model.chat(USER) == model.chat(USER) == "once"
    assert len(model.calls) == 1
    assert model.usage.snapshot().cache_hits == 1


def test_replay_miss_names_the_missing_request(tmp_path):
    cache = ResponseCache(tmp_path / "empty.sqlite", "replay")
    model = ScriptedModel(["never used"], cache=cache)
    with pytest.raises(CacheMissError) as info:
        model.chat([Message(role="user", content="Stack all the blocks " + "x" * 500)])
    message = str(info.value)
    assert "Stack all the blocks" in message and "x" * 150 in message and "x" * 300 not in message
    request = ChatRequest(messages=[Message(role="user", content="Stack all the blocks " + "x" * 500)])
    assert ResponseCache.key("scripted", "scripted", request) in message
    assert model.calls == []


def test_off_mode_neither_reads_nor_writes(tmp_path):
    path = tmp_path / "off.sqlite"
    model = ScriptedModel(["a", "b"], cache=ResponseCache(path, "off"))
    assert [model.chat(USER), model.chat(USER)] == ["a", "b"]
    assert not path.exists()


def test_bad_mode_lists_valid_modes(tmp_path):
    with pytest.raises(ValueError, match="record, replay, off"):
        ResponseCache(tmp_path / "x.sqlite", "replay-ish")


def _png(value: int) -> ImagePart:
    return ImagePart.from_array(np.full((4, 4, 3), value, dtype=np.uint8))


def test_key_depends_on_everything_that_shapes_the_answer():
    def key(**changes) -> str:
        base = dict(
            messages=[Message(role="user", content=[TextPart(text="look"), _png(10)])],
            temperature=0.0, max_tokens=64, seed=0, json_schema=Choice.model_json_schema(),
        )
        base.update(changes)
        version = base.pop("version", "v1")
        backend = base.pop("backend", "openai")
        model = base.pop("model", "m")
        return ResponseCache.key(backend, model, ChatRequest(**base), version)

    reference = key()
    assert key() == reference  # content-addressed: equal requests, equal keys
    variants = [
        key(messages=[Message(role="user", content=[TextPart(text="look"), _png(11)])]),
        key(messages=[Message(role="user", content=[TextPart(text="look!"), _png(10)])]),
        key(temperature=0.7),
        key(max_tokens=65),
        key(seed=1),
        key(json_schema=None),
        key(version="v2"),
        key(backend="llama.cpp"),
        key(model="other"),
    ]
    assert len(set(variants)) == len(variants) and reference not in variants


def test_http_backend_replays_without_touching_the_server(tmp_path):
    path = tmp_path / "http.sqlite"
    with FaultServer() as server:
        server.default = Ok('{"better": 1}')

        def model(mode: str) -> BackendModel:
            backend = OpenAIBackend("fake", base_url=server.base_url, api_key="k",
                                    retry=RetryPolicy(max_attempts=1))
            return BackendModel(backend, cache=ResponseCache(path, mode))

        recorded = model("record").structured(USER, Choice)
        assert len(server.requests) == 1
        replayed = model("replay").structured(USER, Choice)
        assert replayed == recorded == Choice(better=1)
        assert len(server.requests) == 1


def _writer(path: str, worker: int, n: int) -> None:
    cache = ResponseCache(path)
    for i in range(n):
        cache.put(f"{worker}-{i}", Completion(text=f"answer {worker} {i}"), backend="b", model="m")
    cache.close()


def test_several_processes_write_one_cache(tmp_path):
    path = str(tmp_path / "shared.sqlite")
    ctx = mp.get_context("fork")
    workers = [ctx.Process(target=_writer, args=(path, w, 40)) for w in range(3)]
    for p in workers:
        p.start()
    for p in workers:
        p.join(timeout=60)
    assert [p.exitcode for p in workers] == [0, 0, 0]
    cache = ResponseCache(path, "replay")
    assert len(cache) == 120
    assert cache.get("2-39").text == "answer 2 39"


def test_answers_of_one_server_are_not_replayed_for_another(tmp_path, monkeypatch):
    """C1: keys named no server, so a cache recorded from one server answered for any other
    serving a model of the same name (a local `qwen` and a hosted `qwen` mixed silently)."""
    monkeypatch.delenv("ACTIVEINTENT_CACHE_LEGACY_KEYS", raising=False)
    user = [Message(role="user", content="Which bowl?")]
    path = tmp_path / "cache.sqlite"
    with FaultServer() as local, FaultServer() as hosted:
        local.default, hosted.default = Ok("local answer"), Ok("hosted answer")

        def qwen(server, **kw):
            return BackendModel(OpenAIBackend("qwen", base_url=server.base_url, api_key="k"),
                                cache=ResponseCache(path, "record", **kw))

        assert qwen(local).chat(user) == "local answer"
        assert qwen(hosted).chat(user) == "hosted answer"  # not the local server's, from the cache
        assert len(hosted.requests) == 1
        assert qwen(local).chat(user) == "local answer" and len(local.requests) == 1  # still cached per server

        # An entry recorded before keys named servers is read only when asked for explicitly.
        old = ResponseCache(path, "record")
        request = ChatRequest(messages=user, seed=0)
        old.put(old.key("openai", "qwen", request), Completion(text="old answer"), backend="openai", model="qwen")
        with FaultServer() as third:
            third.default = Ok("third answer")
            assert qwen(third).chat(user) == "third answer"
            assert qwen(third, legacy_keys=False).chat(user) == "third answer"
        with FaultServer() as fourth:
            assert qwen(fourth, legacy_keys=True).chat(user) == "old answer" and fourth.requests == []
            monkeypatch.setenv("ACTIVEINTENT_CACHE_LEGACY_KEYS", "1")
            assert qwen(fourth).chat(user) == "old answer" and fourth.requests == []
