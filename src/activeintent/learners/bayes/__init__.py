"""Bayesian active learners (methods ``bayes-preference`` and ``bayes-stop``): an explicit
belief over a grammar of intentions, queries chosen by expected information gain."""

from activeintent.learners.bayes.learner import (
    BayesConfig,
    BayesLearner,
    BayesPreferenceLearner,
    BayesStopLearner,
)

__all__ = ["BayesConfig", "BayesLearner", "BayesPreferenceLearner", "BayesStopLearner"]
