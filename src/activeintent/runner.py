"""Wiring one episode from its :class:`~activeintent.spec.RunSpec`: models, learner, executor,
env, user.

`activeintent run`, `activeintent bench`, `activeintent serve` and the Python API all build
episodes here, so a run means the same thing everywhere.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import BaseModel

from activeintent.act.executors import EXECUTORS, make_executor
from activeintent.envs import ENVS, make_env
from activeintent.episode import Episode
from activeintent.learners.registry import LearnerContext, Method, get_method
from activeintent.llm.models import Models
from activeintent.spec import DEFAULT_INTENTION, DEFAULT_METHOD, LearnerSpec, RunSpec
from activeintent.suites import resolve as resolve_intention
from activeintent.suites.truth_goals import truth_tracker
from activeintent.users.simulated import USER_PRESETS, SimulatedUser, user_profile

__all__ = ["DEFAULT_INTENTION", "DEFAULT_METHOD", "RunSpec", "build_episode", "check_spec", "for_method"]


def for_method(spec: RunSpec, name: str) -> RunSpec:
    """The spec with method ``name`` and, of its settings, those that are that method's (a
    benchmark gives one set of settings to methods of different kinds)."""
    own = get_method(name, spec.plugins).own(spec.learner.settings)
    return spec.model_copy(update={"learner": LearnerSpec(method=name, settings=own)})


def _checked(spec: RunSpec) -> tuple[RunSpec, Method, BaseModel, Models]:
    name = spec.learner.method
    method = get_method(name, spec.plugins)
    settings = method.configure(name, spec.learner.settings)
    spec = spec.model_copy(update={"learner": LearnerSpec(method=name, settings=settings.model_dump(mode="json"))})
    ENVS.check(spec.env.name)
    USER_PRESETS.check(spec.user.preset)
    if method.needs_llm and spec.models.llm == "none":
        raise ValueError(f"--method {name} needs a language model; --llm none is only for methods "
                         "that need none (bayes-*, zero-signal, random-query*).")
    EXECUTORS.check(spec.act.executor)
    return spec, method, settings, Models(spec.models)


def check_spec(spec: RunSpec) -> RunSpec:
    """Refuse, before any work, a spec that cannot run; messages name the option and list choices.
    Returns the spec that will run: the method's settings whole, its defaults filled in."""
    return _checked(spec)[0]


def build_episode(
    spec: RunSpec,
    out_dir: str | Path | None = None,
    user=None,
    observers: list | None = None,
    env=None,
    show_final: str | None = None,
) -> Episode:
    """Everything before the loop starts. Errors in the spec are raised here, before any work.
    ``show_final``: see :class:`Episode` (the web study's final attempt; None for every run)."""
    spec, method, settings, models = _checked(spec)
    who = spec.user
    intention = resolve_intention(who.intention or (None if who.intention_file else DEFAULT_INTENTION),
                                  who.intention_file)
    seeds = spec.seeds  # the one split of the seed: the learner's and the user's streams come from it
    llm = models.llm
    learner = method(LearnerContext(llm=llm, vlm=models.vlm, learner_seed=seeds.learner, settings=settings))
    executor = make_executor(spec.act.executor, model=models.executor_llm if llm is not None else None,
                             parser_first=learner.executor_parses_first)
    if user is None:
        user = SimulatedUser(intention, method.signal, user_profile(who.preset), rng=seeds.user)
        if spec.protocol.new_scene == "off":
            user.profile = user.profile.model_copy(update={"new_scene_false": 0.0, "new_scene_miss": 1.0})
    observers = list(observers or [])
    if getattr(intention, "goal", None) is not None:  # a goal as the hidden intention: track p(goal)
        if (tracker := truth_tracker(learner, intention)) is not None:
            observers.append(tracker)
    return Episode(learner, intention, user, executor, env or make_env(spec.env.name), spec.protocol, observers,
                   usage=models.usage, model_time=models.model_time,
                   extra_config={"spec": spec.model_dump(mode="json", exclude={"plugins"})}, out_dir=out_dir,
                   show_final=show_final)
