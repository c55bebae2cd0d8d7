"""Methods (learners) by command-line name: the paper's, ours, and the baselines.

``bayes-<signal>`` exists for every registered signal, plug-ins included. Register your own
learner with ``METHODS.register("name", Method(...))`` in a file passed with ``--plugin``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from activeintent.learners.base import Learner, LearnerContext, Method
from activeintent.learners.bayes.learner import (
    BayesConfig,
    BayesLearner,
    BayesSettings,
    RandomQueryLearner,
    ZeroSignalLearner,
)
from activeintent.learners.lang.learner import lang_method, lang_zero_signal
from activeintent.learners.paper import faithful as f
from activeintent.learners.paper import structured as p
from activeintent.learners.reward.learner import RewardLearner
from activeintent.registry import Registry, UnknownName, load_plugin
from activeintent.signals import SIGNALS

METHODS: Registry[Method] = Registry("method")


def _bayes(signal: str, kind: str = "eig") -> Callable[[LearnerContext], Learner]:
    cls = {"eig": BayesLearner, "random": RandomQueryLearner, "zero": ZeroSignalLearner}[kind]

    def build(ctx: LearnerContext) -> Learner:
        return cls(signal, rng=ctx.learner_seed, llm=ctx.llm, config=BayesConfig(**ctx.settings.model_dump()))

    return build


def _paper(kind: str) -> Callable[[LearnerContext], Learner]:
    def build(ctx: LearnerContext) -> Learner:
        s = ctx.settings
        assert isinstance(s, p.PaperSettings)
        if s.variant == "faithful":
            cfg = f.FaithfulConfig(**s.model_dump(), seed=ctx.learner_seed)
            if kind == "preference":
                return f.FaithfulPreferenceLearner(ctx.llm, cfg)  # type: ignore[arg-type]
            if kind == "mllm":
                return f.FaithfulMllmLearner(ctx.vlm or ctx.llm, cfg)  # type: ignore[arg-type]
            return f.FaithfulMllmLlmLearner(ctx.llm, ctx.vlm, retriever=s.retriever, config=cfg)  # type: ignore[arg-type]

        config = p.PaperLearnerConfig(**s.model_dump())
        if kind == "preference":
            return p.PreferenceLearner(ctx.llm, config)  # type: ignore[arg-type]
        if kind == "mllm":
            return p.MllmLearner(ctx.vlm or ctx.llm, config)  # type: ignore[arg-type]
        return p.MllmLlmLearner(ctx.llm, ctx.vlm, retriever=s.retriever, config=config)  # type: ignore[arg-type]

    return build


METHODS.register("preference", lambda: Method("preference", True, _paper("preference"),
                 "the paper's eq. 1–2: the LLM estimates z, then two goals y^a, y^b", "paper", colour="#9467bd",
                 settings=p.PaperSettings))
METHODS.register("mllm", lambda: Method("stop", True, _paper("mllm"),
                 "the paper: one multimodal model reads prompt(h) (eq. 3) and gives z, y", "paper", colour="#8c564b",
                 settings=p.PaperSettings))
METHODS.register("mllm-llm", lambda: Method("stop", True, _paper("mllm-llm"),
                 "the paper's best: a retriever gives r (eq. 4), the LLM gives z, y (eq. 5–6)", "paper", colour="#e377c2",
                 settings=p.PaperSettings))
METHODS.register("bayes-preference", lambda: Method("preference", False, _bayes("preference"),
                 "ours: belief over z, A/B queries by expected information gain", colour="#ff7f0e",
                 compared_with="random-query-preference", settings=BayesSettings))
METHODS.register("bayes-stop", lambda: Method("stop", False, _bayes("stop"),
                 "ours: belief over z, stop queries by expected information gain", colour="#1f77b4",
                 compared_with="random-query", settings=BayesSettings))
METHODS.register("zero-signal", lambda: Method("stop", False, _bayes("stop", "zero"),
                 "baseline: the prior's best guess, asks nothing", "baseline", colour="#7f7f7f",
                 settings=BayesSettings))
METHODS.register("random-query", lambda: Method("stop", False, _bayes("stop", "random"),
                 "baseline: bayes-stop's belief update with random stop queries", "baseline", colour="#aec7e8",
                 settings=BayesSettings))
METHODS.register("random-query-preference", lambda: Method("preference", False, _bayes("preference", "random"),
                 "baseline: bayes-preference's belief update with random A/B queries", "baseline",
                 colour="#ffbb78", settings=BayesSettings))
METHODS.register("lang-stop", lambda: lang_method("stop"))
METHODS.register("lang-preference", lambda: lang_method("preference"))
METHODS.register("lang-zero-signal", lang_zero_signal)


def _reward(signal: str) -> Callable[[LearnerContext], Learner]:
    def build(ctx: LearnerContext) -> Learner:
        return RewardLearner(signal, rng=ctx.learner_seed)

    return build


for _signal in ("preference", "stop"):
    METHODS.register(f"reward-{_signal}", lambda s=_signal: Method(s, False, _reward(s), (
        f"peer: APReL-style reward learning, w·φ(state) over 307 relation features, {s} queries by "
        "mutual information (candidates include the Bayesian planner on its prior)"), "peer",
        colour={"preference": "#bcbd22", "stop": "#17becf"}[s]))

PAPER_METHODS = ("preference", "mllm", "mllm-llm")
BASELINES = ("zero-signal", "lang-zero-signal", "random-query", "random-query-preference")


def _derived() -> dict[str, str]:
    """``bayes-<signal>`` for every registered signal without a method of that name (derived
    when asked, never registered: plug-in signals added later get theirs too)."""
    return {f"bayes-{s}": s for s in SIGNALS.names() if f"bayes-{s}" not in METHODS}


def get_method(name: str, plugins: Iterable[str] = ()) -> Method:
    """The method called ``name``; ``bayes-<signal>`` for any registered signal; ``plugins``:
    files that may register it, loaded first."""
    for path in plugins:
        load_plugin(path)
    if name in METHODS:
        return METHODS.make(name)
    signal = _derived().get(name)
    if signal is None:  # the error lists the derived names too
        raise UnknownName(f"Unknown method {name!r}; valid methods: {', '.join(method_names())}.")
    return Method(signal, False, _bayes(signal), f"ours, for the {signal} signal", settings=BayesSettings)


def check_method(name: str) -> str:
    get_method(name)
    return name


def method_names() -> list[str]:
    return METHODS.names() + list(_derived())


def make_learner(name: str, ctx: LearnerContext) -> Learner:
    return get_method(name)(ctx)


__all__ = ["BASELINES", "METHODS", "PAPER_METHODS", "LearnerContext", "Method", "UnknownName",
           "check_method", "get_method", "make_learner", "method_names"]
