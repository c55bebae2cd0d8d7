"""Method names on the command line → learners."""

from __future__ import annotations

from activeintent.learners.base import Learner
from activeintent.llm.base import ChatModel

PAPER_METHODS = ("preference", "mllm", "mllm-llm")
BAYES_METHODS = ("bayes-preference", "bayes-stop")
METHODS = PAPER_METHODS + BAYES_METHODS
SIGNAL = {"preference": "preference", "mllm": "stop", "mllm-llm": "stop",
          "bayes-preference": "preference", "bayes-stop": "stop"}


def check_method(method: str) -> str:
    if method not in METHODS:
        raise ValueError(f"Unknown method {method!r}; valid methods: {', '.join(METHODS)}.")
    return method


def make_learner(
    method: str,
    *,
    llm: ChatModel | None,
    vlm: ChatModel | None = None,
    retriever: str = "symbolic",
    seed: int = 0,
    design_scenes: bool = True,
    epsilon: float = 2.0,
) -> Learner:
    """Build the learner for ``method``. Paper methods need ``llm``; the Bayesian ones use it
    (when given) only to propose open-ended hypotheses."""
    check_method(method)
    if method in BAYES_METHODS:
        from activeintent.learners.bayes.learner import BayesPreferenceLearner, BayesStopLearner

        cls = BayesPreferenceLearner if method == "bayes-preference" else BayesStopLearner
        return cls(rng=seed, llm=llm)
    from activeintent.learners.paper import (
        MllmLearner,
        MllmLlmLearner,
        PaperLearnerConfig,
        PreferenceLearner,
    )

    if llm is None:
        raise ValueError(f"Method {method!r} needs a language model (--llm).")
    config = PaperLearnerConfig(design_scenes=design_scenes, epsilon=epsilon)
    if method == "preference":
        return PreferenceLearner(llm, config)
    if method == "mllm":
        return MllmLearner(vlm or llm, config)
    if retriever not in ("vision", "symbolic"):
        raise ValueError(f"Unknown retriever {retriever!r}; valid: vision, symbolic.")
    return MllmLlmLearner(llm, vlm, retriever=retriever, config=config)  # type: ignore[arg-type]
