"""Ablation of ``lang-<signal>``: the same learner with a space that never grows.

    bin/activeintent bench --plugin experiments/lang-fixed/lang_fixed.py --methods lang-fixed-stop,lang-stop ...

``lang-fixed-<signal>`` keeps the 3,000 shortest goals it starts from: no neighbours of likely
goals join the belief after an answer (model proposals still would, with ``--llm``).
"""

from activeintent.learners.lang.learner import LangConfig, LangLearner, LangSettings
from activeintent.learners.registry import METHODS, LearnerContext, Method


def _fixed(signal: str) -> Method:
    def build(ctx: LearnerContext) -> LangLearner:
        learner = LangLearner(signal, rng=ctx.learner_seed, llm=ctx.llm,
                              config=LangConfig(**ctx.settings.model_dump(), rejuvenate_top=0))
        learner.name = f"lang-fixed-{signal}"
        return learner

    return Method(signal, False, build, f"ablation: lang-{signal} without neighbours joining the belief",
                  goal_language=True, settings=LangSettings)


for _signal in ("stop", "preference"):
    METHODS.register(f"lang-fixed-{_signal}", lambda s=_signal: _fixed(s))
