"""Model-proposed hypotheses: structured proposal → sandboxed predicate → added to the belief."""

from __future__ import annotations

import numpy as np
import pytest

from activeintent.learners.bayes.facts import facts
from activeintent.learners.bayes.proposals import (
    ProposedIntention,
    SandboxRunner,
    batch_program,
    compile_proposal,
    world_view,
)
from activeintent.learners.bayes.query import scene_state
from activeintent.world import PutIn, Scene, apply_plan

SCENE = Scene(objects=["red block", "blue block", "red bowl", "green bowl"])
RED_IN_GREEN = "return world['in_bowl']['red block'] == 'green bowl'"


def _states():
    start = scene_state(SCENE, 0)
    moved, _ = apply_plan(start, [PutIn(block="red block", bowl="green bowl")])
    return facts(start), facts(moved[-1])


def test_world_view_is_plain_data():
    f, g = _states()
    view = world_view(g)
    assert view["in_bowl"]["red block"] == "green bowl"
    assert eval(repr(view)) == view  # literal data only: safe to embed in a program


def test_batch_program_passes_the_sandbox_guard():
    from activeintent.act.guard import check_program

    f, g = _states()
    check_program(batch_program(RED_IN_GREEN, [world_view(f), world_view(g)]))


@pytest.mark.slow
def test_proposed_predicate_runs_in_the_sandbox_and_hostile_code_is_refused():
    f, g = _states()
    runner = SandboxRunner()
    h = compile_proposal(ProposedIntention(description="Red goes in green.", predicate=RED_IN_GREEN), runner, [f])
    assert h is not None
    h.prefetch([f, g])
    assert (h.holds_f(f), h.holds_f(g)) == (False, True)
    hostile = ProposedIntention(description="Escape.", predicate="import os\nreturn os.system('true') == 0")
    assert compile_proposal(hostile, runner, [f]) is None
    dunder = ProposedIntention(description="Escape.", predicate="return ().__class__.__bases__")
    assert compile_proposal(dunder, runner, [f]) is None


@pytest.mark.slow
def test_learner_adds_model_hypotheses_and_scores_them_on_past_signals():
    from activeintent.learners.base import RoundRecord
    from activeintent.learners.bayes.learner import BayesPreferenceLearner
    from activeintent.learners.bayes.symbolic import symbolic_trajectory
    from activeintent.llm.scripted import ScriptedModel
    from activeintent.signals import PreferenceFeedback

    model = ScriptedModel(
        respond=lambda messages, schema: {
            "hypotheses": [
                {"description": "The red block goes in the green bowl.", "predicate": RED_IN_GREEN},
                {"description": "Broken.", "predicate": "return undefined_name +"},
            ]
        }
    )
    learner = BayesPreferenceLearner(rng=0, llm=model)
    state = scene_state(SCENE, 0)
    plan_a = [PutIn(block="red block", bowl="green bowl")]
    plan_b = [PutIn(block="red block", bowl="red bowl")]
    trajs = [symbolic_trajectory(SCENE, state, p) for p in (plan_a, plan_b)]
    est = learner.estimate(SCENE, state)
    learner.observe(
        RoundRecord(index=0, scene=SCENE, estimate=est, plans=[plan_a, plan_b],
                    feedback=PreferenceFeedback(choice="A")),
        trajs,
    )
    assert "what the user saw" in model.last_prompt.lower()
    names = [h.name for h in learner.hyps]
    assert any(n.startswith("proposed:the red block goes in the green bowl") for n in names)
    assert not any("broken" in n for n in names)  # its code does not compile: not added
    w = {h.name: p for h, p in learner.top(len(learner.hyps))}
    proposed = next(n for n in names if n.startswith("proposed:"))
    assert w[proposed] > 0 and np.isfinite(w[proposed])
