"""ScriptedModel: the test double other areas use to check their prompts."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import BaseModel, Field

from activeintent.llm.base import (
    ImagePart,
    ImagesNotSupportedError,
    Message,
    ModelError,
    StructuredOutputError,
    TextPart,
)
from activeintent.llm.scripted import ScriptedModel


class Goal(BaseModel):
    goal: str
    confidence: float = Field(ge=0, le=1)


def test_queued_answers_and_recorded_messages():
    model = ScriptedModel(["hello", Goal(goal="stack", confidence=0.5), {"goal": "align", "confidence": 1}])
    assert model.chat([Message(role="user", content="hi")]) == "hello"
    assert model.structured([Message(role="user", content="goal?")], Goal).goal == "stack"
    assert model.structured([Message(role="user", content="again")], Goal).goal == "align"
    assert [c.messages[-1].text for c in model.calls] == ["hi", "goal?", "again"]
    assert model.calls[0].json_schema is None
    assert model.calls[1].json_schema == Goal.model_json_schema()
    assert model.last_prompt == "again"


def test_callback_sees_messages_and_schema():
    def respond(messages, schema):
        assert schema is not None and "goal" in schema["properties"]
        return {"goal": messages[-1].text.upper(), "confidence": 0.25}

    model = ScriptedModel(respond=respond)
    assert model.structured([Message(role="user", content="stack")], Goal).goal == "STACK"


def test_invalid_scripted_answer_is_rejected_by_the_schema():
    model = ScriptedModel([{"goal": "stack", "confidence": 3.0}])
    with pytest.raises(StructuredOutputError, match="confidence"):
        model.structured([Message(role="user", content="goal?")], Goal)


def test_running_out_of_answers_is_a_model_error():
    with pytest.raises(ModelError, match="ran out of answers"):
        ScriptedModel([]).chat([Message(role="user", content="hi")])


def test_text_only_model_refuses_images():
    model = ScriptedModel(["never"], accepts_images=False)
    image = ImagePart.from_array(np.zeros((2, 2, 3), dtype=np.uint8))
    with pytest.raises(ImagesNotSupportedError, match="text-only"):
        model.chat([Message(role="user", content=[TextPart(text="see"), image])])
    assert model.calls == []
