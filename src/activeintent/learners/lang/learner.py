"""``lang-<signal>``: the Bayesian active learner over the goal language.

The same learner as ``bayes-<signal>`` (belief, EIG over candidate plans, final answer) with
the language's hypothesis space, and a judge that scores every goal of the space on a state
in one numpy pass instead of one Python call per hypothesis.
"""

from __future__ import annotations

import numpy as np

from activeintent.learners.bayes.facts import facts
from activeintent.learners.bayes.judge import HypothesisJudge, trajectory_steps, utility
from activeintent.learners.bayes.learner import BayesConfig, BayesLearner
from activeintent.learners.lang.hypotheses import LangHypothesis, LangSpace, lang_space
from activeintent.world import WorldState
from activeintent.world.trajectory import Trajectory

KEEP = 3000  # goals kept after de-duplication (the shortest ones)


class LangJudge(HypothesisJudge):
    """Judges outcomes under every goal of one LangSpace at once."""

    def __init__(self, space: LangSpace):
        super().__init__(space.hypotheses)
        self.compiled = space.compiled

    def utility(self, state: WorldState) -> np.ndarray:
        holds, score = self.compiled.eval(facts(state))
        return utility(score, holds)

    def first_away(self, traj: Trajectory) -> np.ndarray:
        hit = self._away.get(id(traj))
        if hit is not None and hit[0] is traj:
            return hit[1]
        out = np.full(self.size, -1)
        for k, (fb, fa, block, ok) in enumerate(trajectory_steps(traj)):
            if fb is fa:
                continue
            _, sb = self.compiled.eval(fb)
            _, sa = self.compiled.eval(fa)
            away = sa < sb - 1e-9
            if ok:
                away = away | self.compiled.moved_off(fb, fa, block)
            out[(out < 0) & away] = k
            if (out >= 0).all():
                break
        if len(self._away) > 4096:
            self._away.clear()
        self._away[id(traj)] = (traj, out)
        return out


class LangLearner(BayesLearner):
    """BayesLearner over the goal language (no model proposals: the language is the space)."""

    def __init__(self, signal, rng=None, llm=None, config: BayesConfig | None = None,
                 hypotheses: tuple[LangHypothesis, ...] | None = None, keep: int = KEEP):
        hyps = hypotheses or lang_space(0, keep).hypotheses
        super().__init__(signal, rng, None, config or BayesConfig(), hyps)
        self.name = f"lang-{self.signal}"
        spaces = {h.space for h in hyps} if all(isinstance(h, LangHypothesis) for h in hyps) else set()
        if len(spaces) == 1 and next(iter(spaces)).hypotheses == tuple(hyps):
            self.judge = LangJudge(next(iter(spaces)))


def lang_method(signal: str):
    """The registry entry of ``lang-<signal>`` (built from a LearnerContext like ``bayes``)."""
    from activeintent.learners.registry import LearnerContext, Method

    def build(ctx: LearnerContext) -> LangLearner:
        return LangLearner(signal, rng=ctx.seed, config=BayesConfig(prior=ctx.prior))  # type: ignore[arg-type]

    return Method(signal, False, build, f"ours: belief over the goal language, {signal} queries by EIG")
