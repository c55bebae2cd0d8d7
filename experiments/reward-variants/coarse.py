"""Ablation of ``reward-<signal>``: the same peer over a coarser feature map.

    bin/activeintent bench --plugin experiments/reward-variants/coarse.py --methods reward-preference-coarse,reward-preference ...

``reward-<signal>-coarse`` keeps the block classes all, warm and cool (not the ten single
colours): 3 × 23 relation features + 8 global ones = 77, about the size of the 82-feature map
the published APReL run used. Fewer directions to pin down with 10 answers; the single-colour
distinctions are lost (docs/reward.md).
"""

from activeintent.learners.registry import METHODS, LearnerContext, Method
from activeintent.learners.reward.features import FEATURE_NAMES
from activeintent.learners.reward.learner import RewardConfig, RewardLearner

COARSE = tuple(i for i, name in enumerate(FEATURE_NAMES) if name.split(":")[0] in ("all", "warm", "cool", "global"))


def _coarse(signal: str) -> Method:
    def build(ctx: LearnerContext) -> RewardLearner:
        learner = RewardLearner(signal, rng=ctx.learner_seed, config=RewardConfig(features=COARSE))
        learner.name = f"reward-{signal}-coarse"
        return learner

    return Method(signal, False, build, f"ablation: reward-{signal} over {len(COARSE)} coarse features", "peer")


for _signal in ("preference", "stop"):
    METHODS.register(f"reward-{_signal}-coarse", lambda s=_signal: _coarse(s))
