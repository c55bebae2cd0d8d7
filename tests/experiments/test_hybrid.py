"""The hybrid of issue #29 (experiments/hybrid/hybrid.py): the goal language's belief and queries with a
reward-feature component, the two model classes weighed by their marginal likelihoods."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from activeintent.learners.reward.belief import RewardBelief
from activeintent.learners.reward.models import RewardModel, RewardObservation
from activeintent.records import read_rounds
from activeintent.registry import load_plugin
from activeintent.runner import RunSpec, build_episode
from activeintent.world import WorldState, layout

PLUGIN = str(Path(__file__).parents[2] / "experiments" / "hybrid" / "hybrid.py")
HybridLearner = load_plugin(PLUGIN).HybridLearner


def rounds_of(method: str, out: Path, signal_seed: int = 4) -> list[dict]:
    spec = RunSpec.from_options(method=method, intention="dev-warm-on-cool", env="symbolic", llm="none",
                                video="none", budget=3, seed=signal_seed, test_scenes=1, curve=False,
                                user="human", plugin=[PLUGIN])
    build_episode(spec, out).run()
    return [{"scene": r["scene"], "plans": r["plans"], "answer": r["answer"]} for r in read_rounds(out / "rounds.jsonl")]


@pytest.mark.parametrize("signal", ["stop"])
def test_the_hybrid_asks_what_lang_asks(tmp_path, signal):
    """The reward component draws from a stream of its own: with one seed the hybrid shows the
    same scenes and plans as lang-<signal> and gets the same answers (a paired comparison)."""
    hybrid = rounds_of(f"hybrid-{signal}", tmp_path / "h")
    assert hybrid == rounds_of(f"lang-{signal}", tmp_path / "l")
    summary = json.loads((tmp_path / "h" / "summary.json").read_text())
    assert 0.0 <= summary["learner_stats"]["p_reward"] <= 1.0
    assert len(summary["diagnostics"]["hybrid"]) == len(hybrid)


def test_the_reward_belief_keeps_the_marginal_likelihood_of_the_answers():
    """log P(h_1..k | M_R) = log mean_m Π_k P(h_k | w_m) over prior draws (no moves, no
    resampling: the identity is exact)."""
    d, n = 4, 400
    model = RewardModel()
    belief = RewardBelief(d, np.random.default_rng(0), model, n=n, moves=0)
    W0 = belief.W.copy()
    rng = np.random.default_rng(1)
    obs = [RewardObservation("preference", 0.05 * rng.standard_normal((2, d)), np.abs(rng.standard_normal((3, d))),
                             choice=c) for c in (0, 2, 1)]
    for o in obs:
        belief.update(o)
    assert belief.ess() >= n / 2  # no resampling happened: the identity below is exact
    direct = np.logaddexp.reduce(sum(o.log_lik(W0, model) for o in obs)) - math.log(n)
    assert belief.log_evidence == pytest.approx(direct, abs=1e-9)


def test_with_the_reward_class_ruled_out_the_answer_is_as_good_under_the_language_as_langs():
    from activeintent.learners.bayes.hypotheses import random_scene

    rng = np.random.default_rng(2)
    hybrid = HybridLearner("preference", 3)
    hybrid.p_reward = lambda: 0.0  # type: ignore[method-assign]
    for _ in range(2):
        scene = random_scene(rng)
        state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
        mine = hybrid.final(scene, state)
        own = hybrid.lang.final(scene, state)
        # its candidates include lang's, so it is at least as likely to satisfy the belief's z
        assert mine.why["p_success"] >= own.why["expected_success"] - 1e-4
    hybrid.p_reward = lambda: 1.0  # type: ignore[method-assign]
    mine = hybrid.final(scene, state)
    assert mine.why["p_success"] > 0 and mine.z.startswith("reward")


def test_an_unknown_decision_is_refused_with_the_valid_ones():
    with pytest.raises(ValueError, match="mixture, map"):
        HybridLearner("preference", 0, decision="vote")
