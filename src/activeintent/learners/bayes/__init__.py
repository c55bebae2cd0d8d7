"""Bayesian active learners (``bayes-<signal>``): an explicit belief over a grammar of
intentions, queries chosen by expected information gain; baselines ``zero-signal`` and
``random-query`` share their belief and update."""

from activeintent.learners.bayes.learner import (
    BayesConfig,
    BayesLearner,
    RandomQueryLearner,
    ZeroSignalLearner,
)

__all__ = ["BayesConfig", "BayesLearner", "RandomQueryLearner", "ZeroSignalLearner"]
