"""Ablation of ``reward-<signal>``: the peer without the Bayesian planner's candidate plans.

    bin/activeintent bench --plugin experiments/reward-variants/noplanner.py --methods reward-preference-noplanner,reward-preference ...

``reward-<signal>-noplanner`` proposes only random skill sequences and greedy one-feature plans
(APReL's own kind of candidates); the product's peer also offers the plans of the Bayesian
learners on their prior (docs/reward.md).
"""

from activeintent.learners.registry import METHODS, LearnerContext, Method
from activeintent.learners.reward.learner import RewardLearner


class NoPlannerRewardLearner(RewardLearner):
    """The peer whose candidates leave out the Bayesian planner's plans."""

    uses_planner = False

    def __init__(self, signal: str, rng=None):
        super().__init__(signal, rng)
        self.name = f"reward-{signal}-noplanner"

    def planner_candidates(self, pool, rng, limit: int, prefixes: bool) -> None:
        return None


def _noplanner(signal: str) -> Method:
    def build(ctx: LearnerContext) -> RewardLearner:
        return NoPlannerRewardLearner(signal, rng=ctx.learner_seed)

    return Method(signal, False, build, f"ablation of reward-{signal}: candidates without the Bayesian planner", "peer",
                  colour={"preference": "#dbdb8d", "stop": "#9edae5"}[signal])


for _signal in ("preference", "stop"):
    METHODS.register(f"reward-{_signal}-noplanner", lambda s=_signal: _noplanner(s))
