"""The OpenAI-compatible path against a local fault-injecting HTTP server on 127.0.0.1."""

from __future__ import annotations

import base64
import io
import socket

import numpy as np
import pytest
from fault_server import Dropped, FaultServer, Hang, Ok, Status, Truncated
from PIL import Image
from pydantic import BaseModel

from activeintent.llm.backend import BackendModel
from activeintent.llm.base import (
    ImagePart,
    Message,
    ModelError,
    ModelUnavailableError,
    StructuredOutputError,
    TextPart,
    TransientModelError,
)
from activeintent.llm.openai_compat import OpenAIBackend
from activeintent.llm.retry import RetryPolicy

FAST = RetryPolicy(max_attempts=3, base_delay_s=0.001, max_delay_s=0.01, seed=7)


class Goal(BaseModel):
    preference: str
    count: int


def make_model(server: FaultServer, *, timeout_s: float = 30.0, retry: RetryPolicy = FAST,
               sleeps: list[float] | None = None, max_repairs: int = 2) -> BackendModel:
    backend = OpenAIBackend(
        "fake-model",
        base_url=server.base_url,
        api_key="test-key",
        timeout_s=timeout_s,
        retry=retry,
        sleep=(sleeps.append if sleeps is not None else lambda s: None),
    )
    return BackendModel(backend, max_repairs=max_repairs)


USER = [Message(role="user", content="Say hello.")]


@pytest.fixture
def server():
    with FaultServer() as srv:
        yield srv


def test_429_then_200_is_retried_with_backoff(server):
    server.script.extend([Status(429, "slow down"), Ok("hello")])
    sleeps: list[float] = []
    model = make_model(server, sleeps=sleeps)
    assert model.chat(USER) == "hello"
    assert len(server.requests) == 2
    assert len(sleeps) == 1 and 0 < sleeps[0] <= FAST.base_delay_s
    totals = model.usage.snapshot()
    assert (totals.calls, totals.retries, totals.prompt_tokens, totals.completion_tokens) == (1, 1, 11, 7)


def test_backoff_grows_exponentially_with_seeded_jitter():
    policy = RetryPolicy(max_attempts=5, base_delay_s=1.0, max_delay_s=100.0, jitter=0.5, seed=3)
    delays = policy.delays()
    assert delays == RetryPolicy(**policy.model_dump()).delays()  # same seed, same waits
    for k, d in enumerate(delays):
        assert 0.5 * 2**k <= d <= 2**k


def test_persistent_500_raises_transient_error_after_all_attempts(server):
    server.default = Status(500, "boom")
    model = make_model(server)
    with pytest.raises(TransientModelError, match="HTTP 500: boom") as info:
        model.chat(USER)
    assert info.value.attempts == FAST.max_attempts
    assert len(server.requests) == FAST.max_attempts
    assert model.usage.snapshot().errors == 1


def test_hang_past_timeout_is_a_transient_error(server):
    server.default = Hang()
    model = make_model(server, timeout_s=0.3, retry=FAST.model_copy(update={"max_attempts": 2}))
    with pytest.raises(TransientModelError, match="timed out") as info:
        model.chat(USER)
    assert info.value.attempts == 2
    assert len(server.requests) == 2


def test_truncated_json_body_is_retried(server):
    server.script.extend([Truncated("hello"), Ok("hello again")])
    model = make_model(server)
    assert model.chat(USER) == "hello again"
    assert len(server.requests) == 2


def test_truncated_json_every_time_raises_typed_error(server):
    server.default = Truncated("x")
    with pytest.raises(TransientModelError, match="truncated"):
        make_model(server).chat(USER)


def test_dropped_connection_is_retried(server):
    server.script.extend([Dropped("lost"), Ok("made it")])
    assert make_model(server).chat(USER) == "made it"
    assert len(server.requests) == 2


def test_nothing_listening_is_model_unavailable():
    with socket.socket() as s:  # a port that was free a moment ago, now closed
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    backend = OpenAIBackend("m", base_url=f"http://127.0.0.1:{port}/v1", retry=FAST,
                            sleep=lambda s: None)
    with pytest.raises(ModelUnavailableError, match="nothing answers"):
        BackendModel(backend).chat(USER)


def test_auth_failure_is_not_retried(server):
    server.default = Status(401, "bad key")
    with pytest.raises(ModelUnavailableError, match="401"):
        make_model(server).chat(USER)
    assert len(server.requests) == 1


def test_missing_key_without_base_url_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    monkeypatch.delenv("OPENAI_BASE_URL", raising=False)
    with pytest.raises(ModelUnavailableError, match="OPENAI_API_KEY"):
        OpenAIBackend("gpt-4o-mini")


def test_local_server_takes_a_dummy_key(server, monkeypatch):
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    monkeypatch.setenv("OPENAI_BASE_URL", server.base_url)
    server.default = Ok("hi")
    assert BackendModel(OpenAIBackend("local", retry=FAST)).chat(USER) == "hi"


def test_images_are_sent_as_base64_png_data_urls(server):
    rgb = np.zeros((8, 6, 3), dtype=np.uint8)
    rgb[2:5, 1:4] = (200, 30, 10)
    image = ImagePart.from_array(rgb)
    server.default = Ok("a red block")
    model = make_model(server)
    assert model.accepts_images
    answer = model.chat(
        [
            Message(role="system", content="You look at tabletop scenes."),
            Message(role="user", content=[TextPart(text="What is on the table?"), image]),
        ]
    )
    assert answer == "a red block"
    sent = server.requests[0]["messages"]
    assert sent[0] == {"role": "system", "content": "You look at tabletop scenes."}
    text_part, image_part = sent[1]["content"]
    assert text_part == {"type": "text", "text": "What is on the table?"}
    assert image_part["type"] == "image_url"
    url = image_part["image_url"]["url"]
    prefix = "data:image/png;base64,"
    assert url.startswith(prefix)
    png = base64.b64decode(url[len(prefix):])
    assert png == image.png
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(png)).convert("RGB")), rgb)


def test_structured_uses_json_schema_response_format(server):
    server.default = Ok('{"preference": "stack", "count": 3}')
    goal = make_model(server).structured(USER, Goal)
    assert goal == Goal(preference="stack", count=3)
    fmt = server.requests[0]["response_format"]
    assert fmt["type"] == "json_schema"
    assert fmt["json_schema"]["name"] == "Goal"
    assert fmt["json_schema"]["schema"] == Goal.model_json_schema()
    assert "JSON schema" in server.requests[0]["messages"][-1]["content"]


def test_server_refusing_formats_falls_back_to_json_object_then_text(server):
    server.script.extend([
        Status(400, "response_format json_schema is not supported"),
        Status(422, "response_format.schema: extra fields not permitted"),
        Status(400, "response_format json_object is not supported"),
        Ok('Sure! ```json\n{"preference": "align", "count": 2}\n```'),
        Ok('{"preference": "align", "count": 4}'),
    ])
    model = make_model(server)
    assert model.structured(USER, Goal) == Goal(preference="align", count=2)
    kinds = [r.get("response_format", {}).get("type") for r in server.requests]
    assert kinds == ["json_schema", "json_object", "json_object", None]
    assert "schema" in server.requests[1]["response_format"]
    assert "schema" not in server.requests[2]["response_format"]
    # The fallback sticks: the next call goes straight to plain text.
    assert model.structured(USER, Goal).count == 4
    assert "response_format" not in server.requests[-1]


def test_unparseable_answer_gets_a_repair_round(server):
    server.script.extend([Ok('{"preference": "stack"}'), Ok('{"preference": "stack", "count": 1}')])
    model = make_model(server)
    assert model.structured(USER, Goal) == Goal(preference="stack", count=1)
    second = server.requests[1]["messages"]
    assert second[-2] == {"role": "assistant", "content": '{"preference": "stack"}'}
    assert "did not parse because" in second[-1]["content"]
    assert "count" in second[-1]["content"]
    assert model.usage.snapshot().repairs == 1


def test_repairs_exhausted_raise_structured_output_error(server):
    server.default = Ok("I think the user likes stacks.")
    model = make_model(server, max_repairs=1)
    with pytest.raises(StructuredOutputError, match="not valid JSON"):
        model.structured(USER, Goal)
    assert len(server.requests) == 2


def test_other_bad_request_is_a_model_error(server):
    server.default = Status(400, "context length exceeded")
    with pytest.raises(ModelError, match="context length exceeded"):
        make_model(server).chat(USER)
