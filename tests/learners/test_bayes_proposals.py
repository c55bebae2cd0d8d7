"""Model-proposed hypotheses: structured proposal → sandboxed predicate → added to the belief
and scored on every past answer."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
from pydantic import ValidationError

from activeintent.envs.symbolic import symbolic_trajectory
from activeintent.goals.facts import facts
from activeintent.learners.base import RoundRecord
from activeintent.learners.bayes import proposals
from activeintent.learners.bayes.judge import HypothesisJudge
from activeintent.learners.bayes.learner import BayesConfig, BayesLearner
from activeintent.learners.bayes.proposals import (
    Proposals,
    ProposedHypothesis,
    ProposedIntention,
    SandboxRunner,
    batch_program,
    compile_proposal,
    world_view,
)
from activeintent.llm.scripted import ScriptedModel
from activeintent.signals.preference import PreferenceAnswer
from activeintent.signals.stop import StopAnswer
from activeintent.world import PutIn, Scene, WorldState, apply_plan, layout

SCENE = Scene(objects=["red block", "blue block", "red bowl", "green bowl"])
RED_IN_GREEN = "return world['in_bowl']['red block'] == 'green bowl'"
RED_IN_RED = "return world['in_bowl']['red block'] == 'red bowl'"
START = WorldState(positions=layout(SCENE, 0))
PLAN_A = [PutIn(block="red block", bowl="green bowl")]
PLAN_B = [PutIn(block="red block", bowl="red bowl")]


def _states():
    moved, _ = apply_plan(START, PLAN_A)
    return facts(START), facts(moved[-1])


class InProcessRunner:
    """Runs predicate bodies in this process (test code only: the bodies are ours), so the
    learner tests do not start a sandbox per batch; counts the worlds it judged."""

    def __init__(self):
        self.judged = 0

    def __call__(self, body: str, worlds: list[dict]) -> list[bool]:
        scope: dict = {}
        exec("def holds(world):\n" + textwrap.indent(body, "    "), scope)  # noqa: S102
        self.judged += len(worlds)
        return [bool(scope["holds"](w)) for w in worlds]


@pytest.fixture
def local_runner(monkeypatch) -> InProcessRunner:
    runner = InProcessRunner()
    monkeypatch.setattr(proposals, "SandboxRunner", lambda: runner)
    return runner


def test_world_view_is_plain_data():
    f, g = _states()
    view = world_view(g)
    assert view["in_bowl"]["red block"] == "green bowl"
    assert world_view(f)["in_bowl"]["red block"] is None
    assert eval(repr(view)) == view  # literal data only: safe to embed in a program


def test_batch_program_passes_the_sandbox_guard():
    from activeintent.act.guard import check_program

    f, g = _states()
    check_program(batch_program(RED_IN_GREEN, [world_view(f), world_view(g)]))


def test_a_proposal_needs_a_sentence_of_at_least_three_words():
    assert ProposedIntention(description="Red goes in green.", predicate=RED_IN_GREEN)
    for bad in ("...", "Escape.", "Red block", "a b c d", "!!! ??? ..."):
        with pytest.raises(ValidationError):
            ProposedIntention(description=bad, predicate=RED_IN_GREEN)
    with pytest.raises(ValidationError):
        Proposals(hypotheses=[{"description": "The red block goes left.", "predicate": "return True"}] * 6)


def test_a_proposed_hypothesis_is_judged_by_its_predicate():
    f, g = _states()
    h = ProposedHypothesis("The red block goes in the green bowl.", RED_IN_GREEN, InProcessRunner())
    assert h.name == "proposed:the red block goes in the green bowl."
    h.prefetch([f, g])
    assert (h.holds_f(f), h.holds_f(g)) == (False, True)
    assert (h.score_f(f), h.score_f(g)) == (0.0, 1.0)
    assert h.feasible(SCENE) and h.plans(START) == []

    def crash(body, worlds):
        raise RuntimeError("sandbox refused")

    broken = ProposedHypothesis("Nothing can ever satisfy this.", RED_IN_GREEN, crash)
    assert not broken.holds_f(g)  # a crashing predicate holds nowhere


@pytest.mark.slow
def test_proposed_predicate_runs_in_the_sandbox_and_hostile_code_is_refused():
    f, g = _states()
    runner = SandboxRunner()
    h = compile_proposal(ProposedIntention(description="Red goes in green.", predicate=RED_IN_GREEN), runner, [f])
    assert h is not None
    h.prefetch([f, g])
    assert (h.holds_f(f), h.holds_f(g)) == (False, True)
    hostile = ProposedIntention(description="Escape the sandbox now.", predicate="import os\nreturn os.system('true') == 0")
    assert compile_proposal(hostile, runner, [f]) is None
    dunder = ProposedIntention(description="Escape the sandbox now.", predicate="return ().__class__.__bases__")
    assert compile_proposal(dunder, runner, [f]) is None


def proposer(*hypotheses: tuple[str, str]) -> ScriptedModel:
    return ScriptedModel(respond=lambda messages, schema: {
        "hypotheses": [{"description": d, "predicate": p} for d, p in hypotheses]})


AGREES = ("The red block goes in the green bowl.", RED_IN_GREEN)
CONTRADICTS = ("The red block goes in the red bowl.", RED_IN_RED)
BROKEN = ("This one does not even compile.", "return undefined_name +")


def first_round(learner: BayesLearner, choice: str = "A"):
    trajs = [symbolic_trajectory(SCENE, START, p) for p in (PLAN_A, PLAN_B)]
    est = learner.estimate(SCENE, START)
    learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, plans=[PLAN_A, PLAN_B],
                                answer=PreferenceAnswer(choice=choice)), trajs)
    return trajs


def test_proposals_are_scored_on_past_answers(local_runner):
    """The user preferred A (red block in the green bowl). Of two proposals added after that
    answer, the one it agrees with must end with more weight than the one it contradicts,
    in exactly the ratio of their likelihoods of that answer."""
    model = proposer(CONTRADICTS, AGREES, BROKEN)
    learner = BayesLearner("preference", rng=0, llm=model)
    trajs = first_round(learner)
    prompt = model.last_prompt.lower()
    assert "what the user saw" in prompt and "preferred goal a" in prompt
    assert local_runner.judged > 0
    names = [h.name for h in learner.hyps]
    agree, contra = "proposed:the red block goes in the green bowl.", "proposed:the red block goes in the red bowl."
    assert agree in names and contra in names
    assert not any("compile" in n for n in names)  # its code does not compile: not added
    w = {h.name: float(p) for h, p in zip(learner.hyps, learner.weights, strict=True)}
    assert np.isfinite(w[agree]) and w[agree] > 3 * w[contra] > 0
    # the ratio is the likelihood ratio of the past answer (both got the same prior mass)
    added = tuple(h for h in learner.hyps if h.name in (agree, contra))
    lik = learner.sig.likelihood(PreferenceAnswer(choice="A"), trajs, HypothesisJudge(added), learner.model)
    assert w[added[0].name] / w[added[1].name] == pytest.approx(lik[0] / lik[1], rel=1e-6)
    stats = learner.stats()
    assert stats["proposal_calls"] == 1 and stats["proposed_kept"] == 2 and stats["proposal_errors"] == []


def test_the_same_proposals_without_a_past_answer_would_tie(local_runner):
    # control: one proposal prefers A, the other B, by the same margin; "can't choose" is
    # equally likely under both, so neither may be favoured
    learner = BayesLearner("preference", rng=0, llm=proposer(AGREES, CONTRADICTS))
    first_round(learner, choice="cant_choose")
    w = {h.name: float(p) for h, p in zip(learner.hyps, learner.weights, strict=True)}
    a, b = w["proposed:the red block goes in the green bowl."], w["proposed:the red block goes in the red bowl."]
    assert a == pytest.approx(b, rel=1e-6)


def test_stop_answers_score_proposals_too(local_runner):
    # A stop learner: proposals have no "moves away" rule, so they expect no stop; a stop
    # after their addition lowers them against hypotheses that predicted it.
    model = proposer(AGREES)
    learner = BayesLearner("stop", rng=0, llm=model)
    traj = symbolic_trajectory(SCENE, START, PLAN_A)
    est = learner.estimate(SCENE, START)
    learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, plans=[PLAN_A], answer=StopAnswer()), [traj])
    i = [h.name for h in learner.hyps].index("proposed:the red block goes in the green bowl.")
    before = learner.weights[i]
    t = traj.time_of(traj.steps[0].reveal_tick) + learner.model.delay_mean
    learner.observe(RoundRecord(index=1, scene=SCENE, estimate=est, plans=[PLAN_A],
                                answer=learner.sig.answer_at(traj, t)), [traj])
    assert learner.weights[i] < before


def test_a_model_error_is_recorded_and_the_answer_still_counts(local_runner):
    # one description is a single word: the structured answer is invalid as a whole
    model = proposer(AGREES, ("Broken.", RED_IN_RED))
    learner = BayesLearner("preference", rng=0, llm=model)
    prior = {h.name: float(w) for h, w in zip(learner.hyps, learner.weights, strict=True)}
    first_round(learner)
    stats = learner.stats()
    assert stats["proposal_calls"] == 1 and len(stats["proposal_errors"]) == 1
    assert stats["proposed_kept"] == 0 and not any(h.name.startswith("proposed:") for h in learner.hyps)
    after = {h.name: float(w) for h, w in zip(learner.hyps, learner.weights, strict=True)}
    assert after["all:in-other-bowl"] > prior["all:in-other-bowl"]  # the answer was still used


def test_no_model_calls_beyond_the_limit(local_runner):
    model = proposer(AGREES)
    learner = BayesLearner("preference", rng=0, llm=model, config=BayesConfig(max_proposal_calls=0))
    first_round(learner)
    assert not model.calls and learner.stats()["proposal_calls"] == 0


@pytest.mark.slow
def test_learner_adds_model_hypotheses_through_the_real_sandbox():
    model = proposer(AGREES, CONTRADICTS, BROKEN)
    learner = BayesLearner("preference", rng=0, llm=model)
    first_round(learner)
    w = {h.name: float(p) for h, p in zip(learner.hyps, learner.weights, strict=True)}
    assert w["proposed:the red block goes in the green bowl."] > 3 * w["proposed:the red block goes in the red bowl."]
    assert not any("compile" in n for n in w)
