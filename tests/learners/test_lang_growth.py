"""The lang learner's growing space: Belief.extend is exact, neighbours, model goals in the language."""

from __future__ import annotations

import json

import numpy as np
import pytest

from activeintent.act.base import make_executor
from activeintent.envs.symbolic import SymbolicEnv
from activeintent.episode import Episode, EpisodeConfig
from activeintent.learners.bayes.belief import Belief
from activeintent.learners.lang.expr import MAX_CLAUSES, Each, Goal, parse_goal
from activeintent.learners.lang.hypotheses import GoalIntention, LangSpace
from activeintent.learners.lang.learner import LangConfig, LangJudge, LangLearner
from activeintent.learners.lang.proposals import goals_schema, neighbours, to_goal
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
            EpisodeConfig(budget=10, seed=3, test_scenes=3, curve=False)).run()
    names = [h.name for h in learner.hyps]
    assert true.key in names
    assert learner.stats()["neighbours"] > 0
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
