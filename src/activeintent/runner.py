"""Wiring one episode from options: models, learner, executor, env, user.

`activeintent run`, `activeintent bench`, `activeintent serve` and the Python API all build
episodes here, so a run means the same thing everywhere. :class:`RunOptions` holds every
option with its default, typed once; the CLI reads its defaults from here.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from activeintent.episode import Episode, EpisodeConfig
from activeintent.protocol import (
    DEFAULT_BUDGET,
    DEFAULT_TEST_POOL,
    DEFAULT_TEST_SCENES,
    NewSceneRule,
)

DEFAULT_METHOD = "bayes-stop"
DEFAULT_INTENTION = "color-match"


class RunOptions(BaseModel):
    """Every option of an episode (the CLI's defaults are these)."""

    model_config = ConfigDict(extra="forbid")

    method: str = DEFAULT_METHOD
    intention: str | None = None
    intention_file: str | None = None
    plugins: list[str] = Field(default_factory=list, description="Python files that register plug-ins")
    budget: int = Field(DEFAULT_BUDGET, ge=0, le=100)
    seed: int = Field(0, ge=0)
    test_seed: int | None = Field(None, ge=0)
    test_scenes: int = Field(DEFAULT_TEST_SCENES, ge=1, le=200)
    test_pool: int = Field(DEFAULT_TEST_POOL, ge=0, le=1000)
    env: str = "pybullet"
    user: str = "human"
    new_scene: NewSceneRule = "counted"
    prior: str = Field("length", pattern="^(length|uniform)$")
    llm: str = "embedded"
    vlm: str | None = None
    base_url: str | None = None
    cache: str | None = None
    cache_mode: str = Field("record", pattern="^(record|replay|off)$")
    executor: str = "plan"
    retriever: str = Field("symbolic", pattern="^(symbolic|vision)$")
    epsilon: float = Field(2.0, ge=0)
    early_threshold: float = Field(2.0, ge=0)
    variant: str = Field("faithful", pattern="^(faithful|structured)$")
    design_scenes: bool = True
    video: str = Field("final", pattern="^(none|final|all)$")
    curve: bool = True
    stop_when_done: bool = False


class Models:
    """The models a run uses, loaded on first use (Bayesian methods may need none)."""

    def __init__(self, options: RunOptions):
        self.options = options
        self._loaded: dict[str, Any] = {}

    def _load(self, spec: str | None):
        if spec is None or spec == "none":
            return None
        if spec not in self._loaded:
            from activeintent.llm.registry import load_model

            o = self.options
            self._loaded[spec] = load_model(spec, base_url=o.base_url, cache_path=o.cache, cache_mode=o.cache_mode)
        return self._loaded[spec]

    @property
    def llm(self):
        return self._load(self.options.llm)

    @property
    def vlm(self):
        return self._load(self.options.vlm)

    def _totals(self):
        return [m.usage.snapshot() for m in self._loaded.values() if m is not None and m.usage is not None]

    def usage(self) -> tuple[int, int, int]:
        t = self._totals()
        return sum(x.calls for x in t), sum(x.prompt_tokens for x in t), sum(x.completion_tokens for x in t)

    def model_time(self) -> float:
        return float(sum(x.latency_s for x in self._totals()))


def check_options(options: RunOptions) -> None:
    """Refuse, before any work, options that cannot run; messages name the option and list choices."""
    from activeintent.envs import ENVS
    from activeintent.learners.registry import get_method
    from activeintent.registry import load_plugin
    from activeintent.users.simulated import USER_PRESETS

    for path in options.plugins:
        load_plugin(path)
    method = get_method(options.method)
    ENVS.check(options.env)
    USER_PRESETS.check(options.user)
    if method.needs_llm and options.llm == "none":
        raise ValueError(f"--method {options.method} needs a language model; --llm none is only for methods "
                         "that need none (bayes-*, zero-signal, random-query*).")
    from activeintent.act.executors import EXECUTORS
    from activeintent.llm.registry import parse_spec

    EXECUTORS.check(options.executor)
    for spec in (options.llm, options.vlm):
        if spec not in (None, "none"):
            parse_spec(spec)  # a typo in a model spec is refused before any work


def build_episode(
    options: RunOptions,
    out_dir: str | Path | None = None,
    user=None,
    observers: list | None = None,
    env=None,
    show_final: str | None = None,
) -> Episode:
    """Everything before the loop starts. Errors in the options are raised here, before any work.
    ``show_final``: see :class:`Episode` (the web study's final attempt; None for every run)."""
    from activeintent.act.executors import make_executor
    from activeintent.envs import make_env
    from activeintent.learners.registry import LearnerContext, get_method
    from activeintent.suites import resolve as resolve_intention
    from activeintent.users.simulated import SimulatedUser, user_profile

    check_options(options)
    method = get_method(options.method)
    intention = resolve_intention(options.intention or (None if options.intention_file else DEFAULT_INTENTION),
                                  options.intention_file)
    models = Models(options)
    config = EpisodeConfig(budget=options.budget, seed=options.seed, test_seed=options.test_seed,
                           test_scenes=options.test_scenes, test_pool=options.test_pool, new_scene=options.new_scene, curve=options.curve,
                           video=options.video, stop_when_done=options.stop_when_done)
    seeds = config.seeds  # the one split of the seed: the learner's and the user's streams come from it
    llm = models.llm
    learner = method(LearnerContext(llm=llm, vlm=models.vlm, retriever=options.retriever, learner_seed=seeds.learner,
                                    design_scenes=options.design_scenes, epsilon=options.epsilon,
                                    prior=options.prior, variant=options.variant,
                                    early_threshold=options.early_threshold))
    executor = make_executor(options.executor, model=llm, parser_first=options.variant == "structured")
    if user is None:
        user = SimulatedUser(intention, method.signal, user_profile(options.user), rng=seeds.user)
        if options.new_scene == "off":
            user.profile = user.profile.model_copy(update={"new_scene_false": 0.0, "new_scene_miss": 1.0})
    observers = list(observers or [])
    if getattr(intention, "goal", None) is not None:  # a goal as the hidden intention: track p(goal)
        from activeintent.bench.truth_goals import truth_tracker

        if (tracker := truth_tracker(learner, intention)) is not None:
            observers.append(tracker)
    return Episode(learner, intention, user, executor, env or make_env(options.env), config, observers,
                   usage=models.usage, model_time=models.model_time,
                   extra_config={"options": options.model_dump(mode="json")}, out_dir=out_dir,
                   show_final=show_final)
