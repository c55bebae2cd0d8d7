"""The HTTP path end to end: our OpenAI client against llama.cpp's own server on 127.0.0.1."""

from __future__ import annotations

from typing import Literal

import pytest
from pydantic import BaseModel

from activeintent.llm.base import Message
from activeintent.llm.cache import ResponseCache
from activeintent.llm.registry import load_model

pytestmark = pytest.mark.slow


class Pick(BaseModel):
    color: Literal["red", "green", "blue"]
    count: int


ASK = [Message(role="user", content="There are two red blocks and one blue block. Which color "
                                    "is most common, and how many blocks of it are there?")]


def test_structured_answer_over_http(llama_server):
    model = load_model("openai:gemma-3-270m", base_url=llama_server, cache_mode="off")
    answer = model.structured(ASK, Pick, max_tokens=40)
    assert isinstance(answer, Pick)
    # llama-cpp-python's server refuses json_schema and takes json_object + schema (a grammar).
    assert model.backend._format_mode == 1
    totals = model.usage.snapshot()
    assert totals.calls == 1 and totals.prompt_tokens > 0 and totals.completion_tokens > 0
    model.close()


def test_free_text_and_cache_replay_over_http(llama_server, tmp_path):
    path = tmp_path / "responses.sqlite"
    recorder = load_model("openai:gemma-3-270m", base_url=llama_server, cache=ResponseCache(path))
    recorded = (recorder.chat(ASK, max_tokens=12), recorder.structured(ASK, Pick, max_tokens=40))
    # Replay never calls the server (a miss is a CacheMissError); its keys name the server's URL.
    replayer = load_model("openai:gemma-3-270m", base_url=llama_server, cache=ResponseCache(path, "replay"))
    replayed = (replayer.chat(ASK, max_tokens=12), replayer.structured(ASK, Pick, max_tokens=40))
    assert replayed == recorded
    assert replayer.usage.snapshot().cache_hits == 2
