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


def test_a_plug_in_signal_gets_its_bayes_method_without_anything_registered_on_lookup():
    from activeintent.learners.registry import METHODS
    from activeintent.signals import SIGNALS
    from activeintent.signals.stop import StopSignal

    before = METHODS.names()
    SIGNALS.register("stop-again", StopSignal)
    try:
        assert "bayes-stop-again" in method_names()
        assert get_method("bayes-stop-again").signal == "stop-again"
        assert METHODS.names() == before  # derived, not registered
    finally:
        SIGNALS._factories.pop("stop-again")  # the registry is process-wide: leave it as found
    assert "bayes-stop-again" not in method_names()
