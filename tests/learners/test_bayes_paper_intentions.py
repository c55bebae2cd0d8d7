"""The Bayesian learners identify each of the paper's four intentions with an exact user
within K = 5 signals, through the real episode loop (symbolic env, no language model).

Each intention runs with one signal (the two signals alternate) to keep the file quick;
tests/learners/test_bayes_learner.py runs both signals over several seeds on a library
intention.
"""

from __future__ import annotations

from functools import cache

import pytest

from activeintent.runner import RunSpec, build_episode

# the hypothesis of the grammar that agrees with each intention
EXPECTED_TOP = {"align": "all:row", "stack": "all:tower", "color-match": "all:in-same-bowl",
                "color-mismatch": "all:in-other-bowl"}
SEED = 11


@cache
def episode(method: str, intention: str):
    options = RunSpec.from_options(method=method, intention=intention, env="symbolic", llm="none", user="exact",
                         video="none", seed=SEED, curve=False)
    result = build_episode(options).run()
    assert result.error is None, result.error
    return result


@pytest.mark.slow
@pytest.mark.parametrize("intention, method", [("align", "bayes-stop"), ("stack", "bayes-preference"),
                                               ("color-match", "bayes-stop"),
                                               ("color-mismatch", "bayes-preference")])
def test_identifies_each_paper_intention_with_an_exact_user_within_5_signals(intention, method):
    r = episode(method, intention)
    assert r.signals_used == r.budget == 5 and r.success == 1.0
    assert r.success > episode("zero-signal", intention).success
    # the learner's top hypotheses include the one that agrees with the intention
    assert EXPECTED_TOP[intention] in [name for name, _ in r.learner_stats["top"][:2]]
