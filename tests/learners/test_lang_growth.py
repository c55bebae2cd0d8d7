"""The lang learner's growing space: Belief.extend is exact, neighbours, model goals in the language."""

from __future__ import annotations

import json

import numpy as np
import pytest

from activeintent.act.executors import make_executor
from activeintent.envs.symbolic import SymbolicEnv
from activeintent.episode import Episode
from activeintent.goals.language import MAX_CLAUSES, Each, Goal, parse_goal
from activeintent.learners.bayes.belief import Belief
from activeintent.learners.lang.hypotheses import GoalIntention, LangSpace
from activeintent.learners.lang.learner import LangConfig, LangJudge, LangLearner
from activeintent.learners.lang.proposals import goals_schema, neighbours, to_goal
from activeintent.spec import ProtocolConfig
from activeintent.users.simulated import SimulatedUser, user_profile

WARM_LEFT = Each("every", "class", "warm", "region", "left half")
COOL_RIGHT = Each("every", "class", "cool", "region", "right half")


@pytest.mark.parametrize("prior", ["length", "uniform"])
def test_extending_the_belief_equals_enumerating_everything_from_the_start(prior):
    rng = np.random.default_rng(0)
    goals = [Goal((c,)) for c in (WARM_LEFT, COOL_RIGHT)] + [
        Goal((Each(q, "all", "", "in-bowl", p),)) for q in ("every", "none", "at-least-1") for p in ("any", "same", "other")]
    hyps = LangSpace(goals).hypotheses
    lik = rng.uniform(0.01, 1.0, size=(4, len(hyps)))
    full = Belief(hyps, prior)
    for row in lik:
        full.update(row)
    part = Belief(hyps[:5], prior)
    for row in lik:
        part.update(row[:5])
    part.extend(hyps[5:], np.log(lik[:, 5:]).sum(0))
    assert np.allclose(part.weights, full.weights)
    assert part.log_evidence == pytest.approx(full.log_evidence)
    assert part.log_norm == pytest.approx(full.log_norm)


def test_neighbours_are_one_move_away_and_parse_back():
    g = Goal((WARM_LEFT,))
    other = Goal((COOL_RIGHT,))
    got = {n.key: n for n in neighbours([g, other])}
    assert g.key not in got and other.key not in got
    assert Goal((WARM_LEFT,), True).key in got  # stays toggled
    assert Goal((Each("none", "class", "warm", "region", "left half"),)).key in got  # quantifier
    assert Goal((Each("every", "class", "cool", "region", "left half"),)).key in got  # selector
    assert Goal((Each("every", "class", "warm", "region", "back half"),)).key in got  # parameter
    joined = Goal(tuple(sorted((WARM_LEFT, COOL_RIGHT), key=lambda c: c.key)))
    assert joined.key in got  # two likely goals joined
    for key, n in got.items():
        assert 1 <= len(n.clauses) <= MAX_CLAUSES
        assert parse_goal(key) == n


def test_a_set_of_colours_is_one_move_per_colour_away():
    """Picking two colours is two choices: a pair is reached from a selector naming one of them."""
    def selectors(clause):
        return {(n.clauses[0].sel, n.clauses[0].sp) for n in neighbours([Goal((clause,))]) if len(n.clauses) == 1}

    red = selectors(Each("every", "colour", "red", "in-bowl", "any"))
    assert ("colours", "red+green") in red and ("all-but-colours", "green+yellow") not in red
    assert not any(sel == "colours" and "red" not in sp.split("+") for sel, sp in red)
    every = selectors(Each("every", "all", "", "in-bowl", "any"))
    assert ("colour", "red") in every and not any(sel.endswith("colours") for sel, _ in every)
    pair = selectors(Each("every", "colours", "blue+red", "in-bowl", "any"))
    assert {("colour", "blue"), ("colours", "red+green"), ("all-but-colours", "blue+red")} <= pair
    assert ("colours", "green+yellow") not in pair


def test_a_conjunction_left_out_of_the_space_joins_it_scored_on_every_answer():
    """The true goal (two clauses) is not in the starting space, its clauses are: after ten
    answers of an exact user it is in the belief with exactly prior × likelihood of every
    answer (as if enumerated from the start), and explains the answers about as well as the
    most probable goal."""
    true = Goal(tuple(sorted((WARM_LEFT, COOL_RIGHT), key=lambda c: c.key)))
    start = [Goal((c,)) for c in (WARM_LEFT, COOL_RIGHT)] + [
        Goal((Each(q, s, p, "region", r),))
        for q in ("every", "none") for s, p in (("all", ""), ("class", "warm"), ("class", "cool"))
        for r in ("left half", "right half", "back half", "front half")]
    start = list({g.key: g for g in start}.values())
    space = LangSpace(start)
    learner = LangLearner("preference", rng=3, hypotheses=space.hypotheses,
                          config=LangConfig(rejuvenate_top=4, max_added=3000))
    assert true.key not in {h.name for h in learner.hyps}
    intention = GoalIntention(true)
    user = SimulatedUser(intention, "preference", user_profile("exact"), rng=3)
    Episode(learner, intention, user, make_executor("plan"), SymbolicEnv(),
            ProtocolConfig(budget=10, seed=3, test_scenes=3, curve=False)).run()
    names = [h.name for h in learner.hyps]
    assert true.key in names
    assert learner.stats()["neighbours"] > 0
    assert all(h.bits > learner.cut for h in learner.hyps[len(start):])  # shorter ones are in the space already
    b = learner.belief
    log_lik = b.log_w + np.array([h.bits for h in b.hyps]) * np.log(2) + b.log_norm + b.log_evidence
    i, top = names.index(true.key), int(np.argmax(learner.weights))
    alone = learner._log_lik(LangJudge(LangSpace([true])))[0]  # the truth scored afresh on every answer
    assert log_lik[i] == pytest.approx(alone)
    assert alone < -1  # the answers did say something
    assert log_lik[i] >= log_lik[top] - 1.0, learner.top(3)


def test_model_answers_become_goals_only_when_their_parts_fit():
    schema = goals_schema(3)
    ok = schema.model_validate({"goals": [
        {"clauses": [{"quantifier": "every", "blocks": "class:warm", "predicate": "region:left half"},
                     {"quantifier": "form", "blocks": "class:cool", "predicate": "form tower:any"}],
         "others_stay": True},
        {"clauses": [{"quantifier": "form", "blocks": "all:", "predicate": "in-bowl:same"}], "others_stay": False},
    ]})
    first, second = (to_goal(g) for g in ok.goals)
    assert first is not None and first.stays and first.key == parse_goal(first.key).key
    assert second is None  # "form" with a relation: no goal of the language
    with pytest.raises(ValueError):  # a word outside the language never validates
        schema.model_validate({"goals": [{"clauses": [{"quantifier": "every", "blocks": "all:",
                                                       "predicate": "juggling:yes"}], "others_stay": False}]})
    enum = json.dumps(schema.model_json_schema())
    assert "region:left half" in enum and "form tower:any" in enum


def test_model_goals_enter_the_belief_with_prior_and_likelihood_only(tmp_path, monkeypatch):
    """``--llm`` on a scripted OpenAI-compatible server: the model is asked for goals under the
    language's schema, the goal that fits joins the belief scored on every answer, the one
    that does not fit is counted and dropped."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from chat_server import LANG_GOAL, ChatServer, schema_name

    from activeintent.learners.lang.proposals import goals_schema as schema
    from activeintent.runner import RunSpec, build_episode

    monkeypatch.setenv("OPENAI_API_KEY", "test")
    with ChatServer() as server:
        opts = RunSpec.from_options(method="lang-stop", intention="color-mismatch", env="symbolic", user="exact",
                          llm="openai:fake", base_url=server.base_url, cache=str(tmp_path / "c.sqlite"),
                          budget=4, test_scenes=2, video="none")
        episode = build_episode(opts, tmp_path / "ep")
        result = episode.run()
    asked = [b for b in server.requests if schema_name(b) == "GoalProposals"]
    assert result.error is None and 1 <= len(asked) <= 3
    assert "region:left half" in json.dumps(asked[0]["response_format"])  # the language's words are the enum
    stats = result.learner_stats
    assert stats["model_answers"] == 2 * len(asked) and stats["model_fit"] == len(asked)
    learner = episode.learner
    model_goal = to_goal(schema(3).model_validate({"goals": [LANG_GOAL]}).goals[0])
    names = [h.name for h in learner.hyps]
    assert model_goal is not None and model_goal.key in names and stats["model_new"] == 1
    b = learner.belief
    i = names.index(model_goal.key)
    log_lik = b.log_w[i] + learner.hyps[i].bits * np.log(2) + b.log_norm + b.log_evidence
    assert log_lik == pytest.approx(learner._log_lik(LangJudge(LangSpace([model_goal])))[0])


@pytest.mark.slow
def test_the_embedded_model_proposes_goals_that_parse_under_the_grammar():
    """The real llama.cpp model decodes under the language's grammar: whatever the small base
    model writes, every clause's words come from the language."""
    from activeintent.learners.lang.proposals import propose_goals
    from activeintent.llm.registry import load_model

    model = load_model("embedded", cache_mode="off")
    likely = [(Goal((WARM_LEFT,)), 0.4), (Goal((COOL_RIGHT,)), 0.3)]
    history = "1. scene: red block, blue block, green bowl; shown: step 1: put the red block in the green bowl; answer: stop"
    goals, answered = propose_goals(model, likely, history, count=2, seed=0)
    assert 1 <= answered <= 2
    for g in goals:
        assert parse_goal(g.key) == g and 1 <= len(g.clauses) <= MAX_CLAUSES


def test_an_episode_does_not_depend_on_the_episodes_run_before_it_in_the_process():
    """The space is shared by the episodes of a process (built once); the planner's verdicts
    of one episode must not leak into the next: same seeds, same episode, whatever ran before
    (this case differed when they leaked)."""
    from activeintent.protocol import trial_seeds
    from activeintent.runner import RunSpec, build_episode

    def run(intention: str):
        seed, test_seed = trial_seeds(0, intention, 0)
        opts = RunSpec.from_options(method="lang-stop", intention=intention, env="symbolic", llm="none", budget=5,
                          video="none", seed=seed, test_seed=test_seed, prior="uniform")
        r = build_episode(opts).run()
        return r.success_at, r.final_z, r.answers

    first = run("align")
    run("stack")
    assert run("align") == first


def test_a_new_lang_learner_forgets_the_planner_failures_marked_in_the_shared_space():
    """Pins ``sp.reset()`` in LangLearner.__init__: goals an earlier episode's planner failed
    on are marked infeasible in the process-wide space; a new learner starts from the static
    checks only, and its episode is the one it would be with a clean space."""
    from activeintent.learners.lang.hypotheses import lang_space
    from activeintent.protocol import trial_seeds
    from activeintent.runner import RunSpec, build_episode

    shared = lang_space()
    seed, test_seed = trial_seeds(0, "align", 0)
    opts = RunSpec.from_options(method="lang-stop", intention="align", env="symbolic", llm="none", budget=3,
                      video="none", seed=seed, test_seed=test_seed, prior="uniform", curve=False)

    class Rounds(list):
        def answered(self, log):
            self.append(log)

    def run():
        rounds = Rounds()
        result = build_episode(opts, observers=[rounds]).run()
        assert result.error is None, result.error
        return result, rounds

    clean, clean_rounds = run()
    scenes = {tuple(r.scene) for r in clean_rounds} | {tuple(t.scene) for t in clean.tests}
    # As an earlier episode's planner failures would: every other goal infeasible in these scenes.
    for objects in scenes:
        shared.failed.setdefault(objects, set()).update(range(0, len(shared.goals), 2))
    some = next(iter(scenes))
    assert not shared.feasible(some)[::2].any()  # the marks are in effect before the learner is built

    learner = LangLearner("stop", config=LangConfig(prior="length"))
    assert learner.base == [shared]
    for objects in scenes:
        assert (learner.judge.feasible(objects) == shared.compiled.possible(objects)).all()

    for objects in scenes:
        shared.failed.setdefault(objects, set()).update(range(0, len(shared.goals), 2))
    again, again_rounds = run()
    assert (again.success_at, again.final_z, again.final_goal, again.answers) == (
        clean.success_at, clean.final_z, clean.final_goal, clean.answers)
    assert [(r.scene, r.plans, r.answer, r.why) for r in again_rounds] == [
        (r.scene, r.plans, r.answer, r.why) for r in clean_rounds]
