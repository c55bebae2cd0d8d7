"""Coverage (bench/coverage.py, `activeintent coverage`, `hypotheses --explain NAME`): the best
goal by behaviour is found for an intention that is a goal, in the right direction; an intention
outside the language is called not expressible; the prior rank counts what it says; held-out
rows stay hidden before a freeze."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from activeintent.bench import coverage as cov
from activeintent.goals.facts import facts
from activeintent.goals.language import parse_goal
from activeintent.intentions.base import Intention
from activeintent.learners.lang.hypotheses import GoalIntention
from activeintent.world import PutAt, WorldState, apply_skill
from activeintent.world.scene import sample_scene

STRIP_X = 0.17  # no region of the language has an edge near here


class OnAStrip(Intention):
    """Every block on the table within 2 cm of the line x = 0.17: outside the language."""

    name = "test-on-a-strip"
    description = "Put every block on the table within 2 cm of the line x = 0.17."

    def satisfied(self, state):
        f = facts(state)
        return all(f.below[b] is None and f.bowl_of[b] is None and abs(f.xy[b][0] - STRIP_X) < 0.02
                   for b in state.blocks)

    def score(self, state):
        f = facts(state)
        return float(np.mean([abs(f.xy[b][0] - STRIP_X) < 0.02 for b in state.blocks]))

    def feasible(self, scene):
        return True

    def sample_scene(self, rng):
        return sample_scene(rng, n_blocks=(2, 3), n_bowls=1)

    def plan(self, state):
        steps = []
        spots = iter(np.linspace(-0.25, -0.75, 11))
        for b in state.blocks:
            for y in spots:
                new, fail = apply_skill(state, PutAt(block=b, position=(STRIP_X, float(y))))
                if fail is None:
                    steps.append(PutAt(block=b, position=(STRIP_X, float(y))))
                    state = new
                    break
            else:
                return None
        return steps


def test_an_intention_that_is_a_goal_is_covered_by_it_with_plan_success_one():
    goal = parse_goal("every all: in-bowl:same")
    got = cov.coverage(GoalIntention(goal), scenes=12, test_scenes=30)
    assert got.success == 1.0 and got.selection_success == 1.0
    assert got.bits <= goal.bits + 1e-9  # the same goal, or one as short that behaves as well


def test_coverage_is_direction_sensitive():
    got = cov.coverage(GoalIntention(parse_goal("every colour:red on-the-block:blue")), scenes=10, test_scenes=20)
    assert got.success >= 0.95
    assert "colour:blue on-the-block:red" not in got.goal


def test_an_intention_outside_the_language_is_not_expressible():
    from activeintent.bench.coverage import explain_intention

    got = cov.coverage(OnAStrip(), scenes=10, test_scenes=20)
    assert got.success < cov.EXPRESSIBLE
    said = explain_intention(OnAStrip())
    assert not said["expressible"] and said["note"].startswith("not expressible (best: ")


def test_the_prior_rank_counts_the_distinct_goals_with_fewer_bits():
    distinct = [8.0, 9.5, 9.5, 11.0, 12.25]
    assert [cov.prior_rank(b, distinct) for b in (7.0, 8.0, 9.5, 10.0, 13.0)] == [1, 1, 2, 4, 6]
    info = cov.start_space_info()
    assert info["distinct_bits"] == sorted(info["distinct_bits"]) and len(info["distinct_bits"]) == info["distinct"]


def test_feasible_scenes_are_seeded_and_feasible():
    it = GoalIntention(parse_goal("every all: in-bowl:same"))
    a = cov.feasible_scenes(it, 8, 0, "selection")
    assert a == cov.feasible_scenes(it, 8, 0, "selection")
    assert a != cov.feasible_scenes(it, 8, 0, "test")
    assert all(it.feasible(scene) for scene, _ in a)


def test_the_plan_success_is_judged_by_the_intention_on_the_plans_end_state():
    it = OnAStrip()
    scenes = cov.feasible_scenes(it, 6, 0, "selection")
    rate, finals = cov.goal_success(parse_goal("every all: region:right half"), scenes, it)
    ends = {k: e for k, e in finals}
    assert rate == sum(it.satisfied(e) for e in ends.values()) / len(scenes)
    assert all(isinstance(e, WorldState) for e in ends.values())


@pytest.fixture
def fake_table(monkeypatch):
    def table(items, groups, **kw):
        rows = [{"suite": g, "intention": it.name, "success": 0.5, "goal": "form tower:any all:", "bits": 9.8,
                 "sentence": "s", "prior_rank": 13, "in_start_space": True} for it, g in zip(items, groups, strict=True)]
        return {"protocol": {}, "intentions": rows,
                "suites": [{"suite": g, "n": 1, "mean": 0.5, "ci": [0.5, 0.5], "expressible": 0, "median_bits": 9.8,
                            "in_start_space": 1} for g in dict.fromkeys(groups)]}

    monkeypatch.setattr(cov, "coverage_table", table)


def test_the_command_hides_held_out_rows_before_a_freeze(fake_table):
    from activeintent.cli import app
    from activeintent.suites import suite

    held, dev = suite("heldout")[0], suite("dev")[0]
    out = CliRunner().invoke(app, ["coverage", "--intentions", f"{held},{dev}"], env={"COLUMNS": "200"})
    assert out.exit_code == 0, out.output
    assert dev in out.output and held not in out.output and "held out" in out.output
    out = CliRunner().invoke(app, ["coverage", "--intentions", f"{held},{dev}", "--after-freeze"],
                             env={"COLUMNS": "200"})
    assert held in out.output


def test_an_unknown_intention_is_a_clear_error():
    from activeintent.cli import app

    out = CliRunner().invoke(app, ["coverage", "--intentions", "no-such-thing"])
    assert out.exit_code == 2 and "Unknown intention" in out.output


def test_the_committed_coverage_comes_out_of_the_code():
    """docs/results/coverage: the rows of two intentions re-measured equal the committed ones."""
    import json
    from pathlib import Path

    from activeintent.goals.language import speaking
    from activeintent.suites import resolve

    committed = json.loads((Path(__file__).resolve().parents[2] / "docs/results/coverage/coverage.json").read_text())
    rows = {r["intention"]: r for r in committed["intentions"]}
    for name in ("stack", "dev-warm-on-cool"):
        with speaking(committed["protocol"].get("language", 1)):  # measured before the language grew
            again = cov.coverage(resolve(name), start_keys=cov.start_space_keys()).row()
        assert {k: again[k] for k in ("goal", "success", "selection_success", "bits", "prior_rank")} == {
            k: rows[name][k] for k in ("goal", "success", "selection_success", "bits", "prior_rank")}, name


def test_the_search_keeps_each_states_verdicts_and_counts_exactly():
    """Packed verdicts and running counts equal the clauses judged afresh on every state."""
    from activeintent.goals.language import Goal, all_clauses
    from activeintent.learners.lang.space import Compiled

    it = OnAStrip()
    scenes = cov.feasible_scenes(it, 3, 0, "selection")
    trials = cov._bank(it, scenes, np.random.default_rng(0))
    clauses = sorted(all_clauses(), key=lambda c: (c.bits, c.key))[:3000]
    search = cov.Search(it, trials, clauses)
    judge = Compiled([Goal((c,)) for c in clauses])
    dense, labels = [], []
    for t in trials:
        possible = judge.possible(tuple(t.scene.objects))[: len(clauses)]
        seen = {}
        for s in t.states:
            seen.setdefault(tuple(sorted(s.positions.items())), s)
        for s in seen.values():
            dense.append(judge.clause_eval(facts(s))[0][: len(clauses)] & possible)
            labels.append(bool(it.satisfied(s)))
    H, y = np.array(dense).T, np.array(labels)
    rows = np.arange(len(clauses))
    assert H.shape[1] == len(search.labels) and (search.y == y).all()
    assert (search.holds(rows) == H).all()
    assert (search.tp == H[:, y].sum(1)).all() and (search.fp == H[:, ~y].sum(1)).all()
    kept = search.comp._tag + ("c",)  # a state's memo keeps none of the search's verdicts (MBs each)
    assert not any(kept in facts(s).memo for t in trials for s in t.states)


def test_coverage_reports_bits_and_rank_under_the_prior_asked_for():
    from activeintent.goals.language import speaking
    from activeintent.goals.prior import goal_bits, load_prior

    with speaking(1):  # language 1: a small space to build
        fitted = load_prior("fitted")
        got = cov.coverage(GoalIntention(parse_goal("every all: in-bowl:same")), scenes=8, test_scenes=10, prior=fitted)
        z = parse_goal(got.goal)
        assert got.bits == round(goal_bits(z, fitted), 2) != round(z.bits, 2)
        assert got.prior_rank == cov.prior_rank(goal_bits(z, fitted), cov.start_space_info(fitted)["distinct_bits"])


def test_coverage_refuses_a_prior_without_bits():
    from activeintent.cli import app

    out = CliRunner().invoke(app, ["coverage", "--intentions", "stack", "--prior", "uniform"])
    assert out.exit_code == 2 and "--prior uniform" in out.output


def test_agreement_scores_a_given_goal_against_a_checker_both_ways():
    """Every block in some bowl against "every block in the bowl of its colour": the checker's
    plan satisfies the looser goal everywhere, the goal's own plan the checker only sometimes."""
    looser = parse_goal("every all: in-bowl:any")
    checker = GoalIntention(parse_goal("every all: in-bowl:same"))
    got = cov.agreement(looser, checker, n=20)
    assert got["scenes"] == 20
    assert got["checker_plan_satisfies_goal"] == 1.0
    assert got["goal_plan_satisfies_checker"] < 1.0
    same = cov.agreement(parse_goal("every all: in-bowl:same"), checker, n=20)
    assert same["checker_plan_satisfies_goal"] == same["goal_plan_satisfies_checker"] == 1.0
