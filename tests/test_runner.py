"""runner.build_episode: what it wires into an episode (the learner's assumptions above all)."""

from __future__ import annotations

import pytest
from pydantic import BaseModel

from activeintent.goals.language import Each, Goal
from activeintent.learners.lang import learner as lang_learner
from activeintent.learners.lang.hypotheses import LangSpace
from activeintent.learners.registry import METHODS, PAPER_METHODS
from activeintent.runner import RunSpec, build_episode
from activeintent.signals import get_signal


def containers(obj, seen=None):
    """``obj`` and every mutable or model object inside it (scalars and strings are left out:
    Python may share those between unrelated objects)."""
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, BaseModel):
        yield obj
        for name in type(obj).model_fields:
            yield from containers(getattr(obj, name), seen)
    elif isinstance(obj, dict):
        yield obj
        for v in obj.values():
            yield from containers(v, seen)
    elif isinstance(obj, list | tuple | set | frozenset):
        if isinstance(obj, list | set):
            yield obj
        for v in obj:
            yield from containers(v, seen)
    elif hasattr(obj, "__dict__") and not isinstance(obj, type):
        yield obj
        for v in vars(obj).values():
            yield from containers(v, seen)


@pytest.fixture
def small_lang_space(monkeypatch):
    """lang-* learners start from a handful of goals (the wiring is the same, the build is instant)."""
    goals = [Goal((Each(q, "all", "", "in-bowl", p),)) for q in ("every", "none") for p in ("any", "same")]
    monkeypatch.setattr(lang_learner, "lang_space", lambda seed=0, keep=0, prior="length", language=None: LangSpace(goals))


@pytest.mark.parametrize("user", ["human", "paper"])
def test_every_learner_assumes_the_signals_learner_model_never_the_users(user, small_lang_space):
    built = []
    for name in METHODS.names():
        method = METHODS.make(name)
        if method.needs_llm:  # cannot be built with --llm none; they have no observation model
            assert name in PAPER_METHODS, f"{name} needs a model: check its assumptions here too"
            continue
        episode = build_episode(RunSpec.from_options(method=name, intention="stack", env="symbolic", llm="none",
                                           user=user, video="none", budget=1))
        learner, simulated = episode.learner, episode.user
        sig = get_signal(method.signal)
        assert hasattr(learner, "model"), f"{name}: the learner's assumed observation model is missing"
        assert learner.model == sig.learner_model(), f"{name} does not assume the signal's learner model"
        assert type(learner.model) is type(simulated.model)
        if type(sig).__module__.startswith("activeintent."):
            # the package's signals give users of these presets other parameters than the learner
            # assumes, so equal values would mean they were copied (a plug-in signal registered by
            # another test, e.g. examples/my_signal.py, may give both the same values)
            assert learner.model != simulated.model, f"{name} assumes the simulated user's true parameters"
        theirs = {id(o) for o in containers(simulated.model)} | {id(o) for o in containers(simulated.profile)}
        shared = [type(o).__name__ for o in containers(learner.model) if id(o) in theirs]
        assert not shared, f"{name} shares objects with the simulated user's model: {shared}"
        built.append(name)
    assert set(built) == set(METHODS.names()) - set(PAPER_METHODS)
    assert {"bayes-stop", "bayes-preference", "zero-signal", "lang-stop", "lang-preference"} <= set(built)
