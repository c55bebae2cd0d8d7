"""Schemas beyond what llama.cpp's grammar can unroll neither crash the process nor fail."""

from __future__ import annotations

import json

import pytest
from pydantic import BaseModel, Field

from activeintent.llm.base import Message, StructuredOutputError
from activeintent.llm.embedded import GRAMMAR_MAX_REPEAT, _loosen


class LongText(BaseModel):
    code: str = Field(max_length=3000)
    items: list[int] = Field(default_factory=list, max_length=5)


def test_long_bounds_are_left_to_validation():
    schema = _loosen(LongText.model_json_schema())
    assert "maxLength" not in json.dumps(schema["properties"]["code"])
    assert schema["properties"]["items"]["maxItems"] == 5 <= GRAMMAR_MAX_REPEAT


def test_the_paper_learners_answer_bounds_are_in_the_grammar():
    """The faithful answer's reasoning, z and y bounds reach the grammar, so a sampled answer
    cannot run on to max_tokens and be cut (it was, and every repair round was cut again)."""
    from activeintent.learners.paper.schemas import (
        FaithfulRetrieval,
        faithful_answer_schema,
        faithful_scene_schema,
    )

    for schema in (faithful_answer_schema(1), faithful_answer_schema(2, with_done=True), FaithfulRetrieval,
                   faithful_scene_schema()):
        props = _loosen(schema.model_json_schema())["properties"]
        for name, prop in props.items():
            if prop.get("type") == "string":
                assert 0 < prop["maxLength"] <= GRAMMAR_MAX_REPEAT, (schema.__name__, name)


@pytest.mark.slow
def test_embedded_answers_a_long_bounded_schema_and_refuses_bad_grammar():
    from llama_cpp import LlamaGrammar
    from llama_cpp.llama_grammar import json_schema_to_gbnf

    from activeintent.llm.registry import load_model

    model = load_model("embedded", cache_mode="off")
    answer = model.structured([Message(role="user", content="Write a tiny Python expression.")], LongText, max_tokens=40)
    assert isinstance(answer, LongText)
    # Whether llama.cpp can unroll a 3000-long bound depends on its version; a grammar it cannot
    # compile at all (a rule that is never defined) must be refused, not crash the process.
    json_schema_to_gbnf(json.dumps(LongText.model_json_schema()))
    bad = LlamaGrammar.from_string('root ::= "a" undefined-rule', verbose=False)
    with pytest.raises(StructuredOutputError):
        model.backend._check_grammar(bad)
