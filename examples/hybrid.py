"""The hybrid of issue #29: ``lang-<signal>`` with a reward-feature component (soft goals).

    bin/activeintent bench --plugin examples/hybrid.py --methods hybrid-preference,hybrid-stop-map ...

The learner is ``activeintent.learners.hybrid`` (its docstring gives the model); it asks what
``lang-<signal>`` asks on the same seed, so a paired comparison with lang-<signal> measures
only what the reward component changes in the final answers (docs/reward.md, "A hybrid").
"""

from activeintent.learners.hybrid import hybrid_method
from activeintent.learners.registry import METHODS

for _signal in ("preference", "stop"):
    METHODS.register(f"hybrid-{_signal}", lambda s=_signal: hybrid_method(s))
    METHODS.register(f"hybrid-{_signal}-map", lambda s=_signal: hybrid_method(s, "map"))
