"""Ablation of ``reward-<signal>``: the same peer with a heavy-tailed prior over w.

    bin/activeintent bench --plugin experiments/reward-variants/heavy_tailed.py --methods reward-preference-heavy-tailed,reward-preference ...

A uniform prior on the sphere (APReL's) spreads belief over all 307 feature directions; the
heavy-tailed one (w = x / ‖x‖, x_i standard Cauchy) makes rewards that weigh a few features
heavily as likely as dense ones (docs/reward.md, "Belief over w").
"""

from activeintent.learners.registry import METHODS, LearnerContext, Method
from activeintent.learners.reward.learner import RewardConfig, RewardLearner


def _heavy_tailed(signal: str) -> Method:
    def build(ctx: LearnerContext) -> RewardLearner:
        return RewardLearner(signal, rng=ctx.learner_seed, config=RewardConfig(prior="heavy-tailed"))

    return Method(signal, False, build, f"ablation: reward-{signal} with a heavy-tailed prior over w", "peer")


for _signal in ("preference", "stop"):
    METHODS.register(f"reward-{_signal}-heavy-tailed", lambda s=_signal: _heavy_tailed(s))
