"""The OpenAI-compatible client against a local server that misbehaves: every call ends by its
deadline, reads at most its size cap, and every malformed answer is a typed ModelError."""

from __future__ import annotations

import json
import time

import pytest
from fault_server import (
    Drip,
    FaultServer,
    Gzip,
    Hang,
    Huge,
    Ok,
    Raw,
    Redirect,
    Status,
    completion_body,
)

from activeintent.llm.backend import BackendModel
from activeintent.llm.base import Message, ModelError, ModelRedirectError, TransientModelError
from activeintent.llm.openai_compat import CallLimits, OpenAIBackend
from activeintent.llm.retry import RetryPolicy

USER = [Message(role="user", content="Say hello.")]
FAST = RetryPolicy(max_attempts=3, base_delay_s=0.001, max_delay_s=0.5, seed=7)


@pytest.fixture
def server():
    with FaultServer() as srv:
        yield srv


def model(server: FaultServer, *, deadline_s: float = 30.0, timeout_s: float = 30.0, max_bytes: int = 2**20,
          retry: RetryPolicy = FAST, sleeps: list[float] | None = None) -> BackendModel:
    backend = OpenAIBackend("fake-model", base_url=server.base_url, api_key="k", timeout_s=timeout_s, retry=retry,
                            sleep=(sleeps.append if sleeps is not None else lambda s: None),
                            limits=CallLimits(deadline_s=deadline_s, max_response_bytes=max_bytes))
    return BackendModel(backend)


def test_a_dripping_server_is_cut_off_at_the_deadline(server):
    """One byte every 0.1 s: every read succeeds, so only an overall deadline ends the call
    (the whole answer would take ~30 s)."""
    server.default = Drip(0.1)
    start = time.monotonic()
    with pytest.raises(TransientModelError, match="deadline of 1 s"):
        model(server, deadline_s=1.0).chat(USER)
    assert time.monotonic() - start < 10  # generous; the drip alone lasts far longer
    assert len(server.requests) == 1  # past the deadline nothing is retried


def test_the_deadline_spans_every_attempt(server):
    """A server that never answers: each attempt times out after timeout_s, and the retries stop
    at the call's deadline instead of running all ten."""
    server.default = Hang()
    retry = FAST.model_copy(update={"max_attempts": 10})
    with pytest.raises(TransientModelError, match="deadline") as info:
        model(server, deadline_s=1.2, timeout_s=0.5, retry=retry).chat(USER)
    assert info.value.attempts < 10 and len(server.requests) < 10


def test_a_huge_body_is_not_read_past_the_cap_nor_retried(server):
    server.default = Huge(300 * 2**20)
    with pytest.raises(ModelError, match="larger than the 1048576 bytes cap"):
        model(server, max_bytes=2**20).chat(USER)
    assert len(server.requests) == 1
    assert server.bytes_sent < 64 * 2**20  # the client stopped reading long before 300 MB


def _body(**over) -> bytes:
    return json.dumps({**completion_body("hi"), **over}).encode()


MALFORMED = {
    "not UTF-8": ('{"choices": [{"message": {"content": "caf\xe9"}}]}'.encode("latin-1"), "not UTF-8"),
    "choices a string": (b'{"choices": "nope"}', "not a chat completion"),
    "no choices": (_body(choices=[]), "not a chat completion"),
    "content a number": (_body(choices=[{"message": {"content": 5}}]), "not a chat completion"),
    "a list": (b"[1, 2]", "not a chat completion"),
    "NaN usage": (_body().replace(b'"prompt_tokens": 11', b'"prompt_tokens": NaN'), "NaN is not a JSON number"),
    "fractional usage": (_body(usage={"prompt_tokens": 1.5, "completion_tokens": 1}), "prompt_tokens"),
    "usage as text": (_body(usage={"prompt_tokens": "11", "completion_tokens": 1}), "prompt_tokens"),
    "negative usage": (_body(usage={"prompt_tokens": -1, "completion_tokens": 1}), "prompt_tokens"),
}


@pytest.mark.parametrize("case", list(MALFORMED))
def test_a_malformed_answer_is_a_typed_model_error(server, case):
    body, why = MALFORMED[case]
    server.default = Raw(body)
    with pytest.raises(TransientModelError, match=why):
        model(server).chat(USER)
    assert len(server.requests) == FAST.max_attempts  # retried like a truncated body


def test_a_valid_raw_answer_still_parses(server):
    server.default = Raw(_body())
    assert model(server).chat(USER) == "hi"


def test_retry_after_is_honoured_when_short_and_reported(server):
    server.script.extend([Status(429, "slow down", {"Retry-After": "0.25"}), Ok("after the wait")])
    sleeps: list[float] = []
    assert model(server, sleeps=sleeps).chat(USER) == "after the wait"
    assert sleeps == [0.25]
    server.default = Status(429, "slow down", {"Retry-After": "0.25"})
    with pytest.raises(TransientModelError, match=r"Retry-After 0.25 s honoured"):
        model(server).chat(USER)


def test_retry_after_too_long_is_ignored_and_says_so(server):
    server.default = Status(503, "busy", {"Retry-After": "3600"})
    sleeps: list[float] = []
    with pytest.raises(TransientModelError, match=r"Retry-After 3600 s ignored: longer than the 0.5 s longest wait"):
        model(server, sleeps=sleeps).chat(USER)
    assert sleeps and max(sleeps) <= FAST.max_delay_s


def test_limits_come_from_the_environment(monkeypatch):
    monkeypatch.setenv("ACTIVEINTENT_MODEL_DEADLINE_S", "2.5")
    monkeypatch.setenv("ACTIVEINTENT_MODEL_MAX_BYTES", "1000")
    limits = CallLimits.from_env()
    assert (limits.deadline_s, limits.max_response_bytes, limits.connect_s) == (2.5, 1000, CallLimits().connect_s)
    monkeypatch.setenv("ACTIVEINTENT_MODEL_DEADLINE_S", "soon")
    with pytest.raises(ValueError, match="ACTIVEINTENT_MODEL_DEADLINE_S"):
        CallLimits.from_env()


def _gzip_bomb(inflated: int) -> bytes:
    """A valid gzip stream of ``inflated`` bytes of spaces (about a thousandth of that on the wire)."""
    import zlib

    z = zlib.compressobj(9, zlib.DEFLATED, 31)
    chunk = b" " * 2**20
    return b"".join(z.compress(chunk) for _ in range(inflated // len(chunk))) + z.flush()


def test_a_gzip_bomb_is_refused_unread(server):
    """L1: the cap counted bytes on the wire, so a 128 KiB gzip body inflated to 128 MiB in the
    client before the size check (a 1 MB body to 1 GiB). Now the client asks for no compression
    and refuses a compressed body without decompressing it, not retried."""
    import tracemalloc

    server.default = Gzip(_gzip_bomb(128 * 2**20))
    client = model(server, max_bytes=2**20)
    tracemalloc.start()
    try:
        with pytest.raises(ModelError, match="compressed with 'gzip'"):
            client.chat(USER)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 16 * 2**20, f"{peak / 2**20:.0f} MiB allocated"
    assert len(server.requests) == 1
    assert server.headers[0]["accept-encoding"] == "identity"


def test_a_redirect_is_not_followed_and_says_where_it_pointed(server):
    """L3: a 307 to another server used to be followed, re-sending the whole prompt there (and the
    run ended exit 0 on the other server's answers)."""
    with FaultServer() as other:
        other.default = Ok("the other server's answer")
        server.default = Redirect(other.base_url + "/chat/completions")
        with pytest.raises(ModelRedirectError, match="redirect to .*127.0.0.1") as info:
            model(server).chat(USER)
        assert info.value.location == other.base_url + "/chat/completions"
        assert other.requests == [] and len(server.requests) == 1


def test_json_nesting_is_bounded_without_recursion():
    """L2 below the client: the depth scan ignores brackets inside strings and never recurses."""
    from activeintent.llm.backend import (
        MAX_JSON_DEPTH,
        TooDeep,
        json_depth,
        loads_bounded,
        parse_structured,
    )
    from activeintent.llm.openai_compat import parse_answer

    assert json_depth('{"a": [[1]], "b": "[[[[\\"[["}') == 3
    assert loads_bounded("[" * MAX_JSON_DEPTH + "]" * MAX_JSON_DEPTH) is not None
    with pytest.raises(TooDeep):
        loads_bounded("[" * (MAX_JSON_DEPTH + 1) + "]" * (MAX_JSON_DEPTH + 1))
    deep = "[" * 200_000 + "]" * 200_000
    with pytest.raises(ValueError, match="nest 200001 deep"):
        parse_answer(('{"choices": ' + deep + "}").encode())
    with pytest.raises(TooDeep):
        parse_structured('{"a": ' + deep + "}", type("S", (), {}))
