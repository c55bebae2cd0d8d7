"""The methods' registry: the command-line name is the one name of a method."""

from __future__ import annotations

import pytest

from activeintent.learners.registry import LearnerContext, get_method, make_learner, method_names
from activeintent.llm.scripted import ScriptedModel


@pytest.mark.parametrize("name", method_names())
def test_a_learner_is_named_as_its_method(name):
    llm = ScriptedModel([]) if get_method(name).needs_llm else None
    learner = make_learner(name, LearnerContext(llm=llm, vlm=llm))
    assert learner.name == name  # records and reports say what the command line said
