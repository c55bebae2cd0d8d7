"""Wiring one episode from its :class:`~activeintent.spec.RunSpec`: models, learner, executor,
env, user.

`activeintent run`, `activeintent bench`, `activeintent serve` and the Python API all build
episodes here, so a run means the same thing everywhere.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel

from activeintent.act.executors import EXECUTORS, make_executor
from activeintent.envs import ENVS, make_env
from activeintent.episode import Episode
from activeintent.learners.registry import LearnerContext, Method, get_method
from activeintent.llm.embedded import EmbeddedConfig
from activeintent.llm.registry import load_model, parse_spec
from activeintent.registry import load_plugin
from activeintent.spec import DEFAULT_INTENTION, DEFAULT_METHOD, LearnerSpec, ModelsConfig, RunSpec
from activeintent.suites import resolve as resolve_intention
from activeintent.suites.truth_goals import truth_tracker
from activeintent.users.simulated import USER_PRESETS, SimulatedUser, user_profile

__all__ = ["DEFAULT_INTENTION", "DEFAULT_METHOD", "Models", "RunSpec", "build_episode", "check_spec", "for_method"]


EXECUTOR_CTX = 8192  # the planner's prompts are ~750 tokens and its answers short


class Models:
    """The models a run uses, loaded on first use (Bayesian methods may need none)."""

    def __init__(self, config: ModelsConfig):
        self.config = config
        self._loaded: dict[str, Any] = {}

    def _load(self, spec: str | None):
        if spec is None or spec == "none":
            return None
        if spec not in self._loaded:
            c = self.config
            self._loaded[spec] = load_model(spec, base_url=c.base_url, cache_path=c.cache, cache_mode=c.cache_mode)
        return self._loaded[spec]

    @property
    def llm(self):
        return self._load(self.config.llm)

    @property
    def vlm(self):
        return self._load(self.config.vlm)

    @property
    def executor_llm(self):
        """The LLM the executor plans with: the same model, but an in-process one gets its own
        KV cache (EXECUTOR_SLOT), so neither the learner's growing conversation nor the
        planner's fixed prompt evicts the other's prefix (the same answers: a kept prefix gives
        the logits of a fresh evaluation)."""
        spec = self.config.llm
        if spec is None or spec == "none" or not (spec == "embedded" or spec.startswith("gguf:")):
            return self.llm
        key = f"{spec}#executor"
        if key not in self._loaded:
            c = self.config
            self._loaded[key] = load_model(spec, base_url=c.base_url, cache_path=c.cache, cache_mode=c.cache_mode,
                                           embedded=EmbeddedConfig(kv_slot="executor", n_ctx=EXECUTOR_CTX))
        return self._loaded[key]

    def _totals(self):
        return [m.usage.snapshot() for m in self._loaded.values() if m is not None and m.usage is not None]

    def usage(self) -> tuple[int, int, int]:
        t = self._totals()
        return sum(x.calls for x in t), sum(x.prompt_tokens for x in t), sum(x.completion_tokens for x in t)

    def model_time(self) -> float:
        return float(sum(x.latency_s for x in self._totals()))


def for_method(spec: RunSpec, name: str) -> RunSpec:
    """The spec with method ``name`` and, of its settings, those that are that method's (a
    benchmark gives one set of settings to methods of different kinds)."""
    for path in spec.plugins:
        load_plugin(path)
    own = get_method(name).own(spec.learner.settings)
    return spec.model_copy(update={"learner": LearnerSpec(method=name, settings=own)})


def _checked(spec: RunSpec) -> tuple[RunSpec, Method, BaseModel]:
    for path in spec.plugins:
        load_plugin(path)
    name = spec.learner.method
    method = get_method(name)
    settings = method.configure(name, spec.learner.settings)
    spec = spec.model_copy(update={"learner": LearnerSpec(method=name, settings=settings.model_dump(mode="json"))})
    ENVS.check(spec.env.name)
    USER_PRESETS.check(spec.user.preset)
    if method.needs_llm and spec.models.llm == "none":
        raise ValueError(f"--method {name} needs a language model; --llm none is only for methods "
                         "that need none (bayes-*, zero-signal, random-query*).")
    EXECUTORS.check(spec.act.executor)
    for model in (spec.models.llm, spec.models.vlm):
        if model not in (None, "none"):
            parse_spec(model)  # a typo in a model spec is refused before any work
    return spec, method, settings


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
    spec, method, settings = _checked(spec)
    who = spec.user
    intention = resolve_intention(who.intention or (None if who.intention_file else DEFAULT_INTENTION),
                                  who.intention_file)
    models = Models(spec.models)
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
