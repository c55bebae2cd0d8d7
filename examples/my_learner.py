"""Your own learner as a plug-in: ``greedy-stop`` and ``greedy-preference`` show the plans of
the goals they currently find most likely, instead of the query with the largest expected
information gain. Everything else (belief over the grammar, Bayes' rule, final answer) is the
Bayesian learner's.

    bin/activeintent run --plugin examples/my_learner.py --method greedy-stop --env symbolic --llm none --intention stack
    bin/activeintent bench --plugin examples/my_learner.py --methods greedy-stop,bayes-stop --suite paper --trials 2 --env symbolic --llm none

A learner is a class with ``design_scene``, ``estimate``, ``observe`` and ``final``
(``activeintent.learners.base.Learner``); a method is its registry entry: the signal it reads,
whether it needs a model, how to build it from a ``LearnerContext`` (seeds, models, settings),
and how reports show it (its colour, the method it is paired with on the same trials).
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from activeintent.learners.bayes.acquisition import Query
from activeintent.learners.bayes.candidates import candidate_plans
from activeintent.learners.bayes.learner import BayesLearner
from activeintent.learners.registry import METHODS, LearnerContext, Method
from activeintent.world import WorldState


class GreedyConfig(BaseModel):
    """The learner's own settings: each field is a setting of its methods, an option of `run`,
    `bench` and `serve` (``--likely 3``) and a field of their records."""

    model_config = ConfigDict(extra="forbid")

    likely: int = Field(2, ge=1, description="Plans come from this many most probable goals")


class GreedyLearner(BayesLearner):
    """Shows what its likeliest goals would have the robot do (a 'show me your best guess' learner)."""

    def __init__(self, signal: str, rng, greedy: GreedyConfig | None = None):
        super().__init__(signal, rng)
        self.greedy = greedy or GreedyConfig()
        self.name = f"greedy-{signal}"

    def _select(self, state: WorldState) -> Query | None:
        feasible = self.judge.feasible(tuple(state.positions))
        outs = candidate_plans(self.hyps, self.weights, state, self.rng, top_k=self.greedy.likely, explore=0,
                               prefixes=self.sig.shows > 1, limit=self.sig.shows, feasible=feasible)
        if len(outs) < self.sig.shows:
            return None
        return Query(outs[:self.sig.shows], 0.0)


def _method(signal: str) -> Method:
    def build(ctx: LearnerContext) -> GreedyLearner:
        return GreedyLearner(signal, rng=ctx.learner_seed, greedy=ctx.settings)  # type: ignore[arg-type]

    # reports pair it with bayes-<signal> (everything but the query choice is the same) and draw it in this colour
    return Method(signal, False, build, f"example: shows the plans of its likeliest goals ({signal})",
                  colour="#393b79", compared_with=f"bayes-{signal}", settings=GreedyConfig)


for _signal in ("stop", "preference"):
    METHODS.register(f"greedy-{_signal}", lambda s=_signal: _method(s))
