"""The truth-goal suite (suites/truth_goals.py, suites/truth_goals.json): drawn for the current
goal language, reproducible from its seed, uniform over the language's structure, every goal
well-formed and showable, and the suite resolves everywhere an intention name is accepted."""

from __future__ import annotations

import os
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from activeintent.bench.report import MIN_SCORED
from activeintent.goals.language import NODES, QUANTS, Each, nodes, parse_goal
from activeintent.learners.lang.hypotheses import GoalIntention
from activeintent.suites import SUITE_NAMES, resolve, suite, suite_of
from activeintent.suites import truth_goals as tg

ROOT = Path(__file__).resolve().parents[2]
DATA = tg.committed()
GOALS = DATA["goals"]


def test_the_committed_suite_is_drawn_for_the_current_language():
    assert DATA["language_version"] == tg.language_version(), (
        "the goal language changed since suites/truth_goals.json was drawn: redraw it with "
        f"`{tg.REDRAW}` (from the repository root, with src on PYTHONPATH) and commit the file")
    settings = tg.settings(DATA["seed"])
    assert {k: DATA[k] for k in settings} == settings, f"the draw's settings changed: `{tg.REDRAW}`"
    assert MIN_SCORED == tg.MIN_SCORED


@pytest.mark.slow
def test_redrawing_with_the_committed_seed_gives_the_committed_suite():
    drawn = tg.draw(DATA["seed"])
    assert [g["key"] for g in drawn["goals"]] == [g["key"] for g in GOALS], f"redraw with `{tg.REDRAW}`"
    assert drawn == DATA


def test_the_draw_is_uniform_over_the_structure_not_the_prior():
    rng = np.random.default_rng(0)
    goals = [tg.random_goal(rng) for _ in range(6000)]
    again = np.random.default_rng(0)
    assert [tg.random_goal(again) for _ in range(20)] == goals[:20]  # a seed fixes the draw
    clauses = [c for g in goals for c in g.clauses]
    each = [c for c in clauses if isinstance(c, Each)]

    def uniform(values, options, tol=0.25):
        counts = Counter(values)
        assert set(counts) == set(options), sorted(set(options) - set(counts))
        mean = len(values) / len(options)
        assert all(abs(n - mean) < tol * mean for n in counts.values()), counts

    uniform([len(g.clauses) for g in goals], range(1, tg.CLAUSE_CAP + 1), 0.1)
    uniform([g.stays for g in goals], (False, True), 0.1)
    uniform([isinstance(c, Each) for c in clauses], (False, True), 0.1)
    uniform([c.quant for c in each], QUANTS)
    uniform([c.sel for c in clauses], nodes("selector", tg.LANGUAGE))  # node types uniform, not by their sizes
    uniform([c.rel for c in each], nodes("relation", tg.LANGUAGE))
    uniform([c.struct for c in clauses if not isinstance(c, Each)], nodes("structure", tg.LANGUAGE))
    uniform([c.sp for c in clauses if c.sel == "class"], NODES["selector"]["class"].params)
    assert all(list(g.clauses) == sorted(g.clauses, key=lambda c: c.key) for g in goals)


def test_every_truth_goal_parses_is_short_showable_and_not_trivial():
    assert len(GOALS) == tg.COUNT == 50
    assert [g["name"] for g in GOALS] == [f"truth-{i:02d}" for i in range(50)]
    assert len({g["key"] for g in GOALS}) == 50
    for g in GOALS:
        goal = parse_goal(g["key"])
        assert goal.key == g["key"] and goal.sentence() == g["sentence"]
        assert 1 <= len(goal.clauses) == g["clauses"] <= tg.CLAUSE_CAP
        feasible, already = tg.measure(goal)
        assert feasible >= tg.MIN_FEASIBLE, (g["name"], feasible)
        assert already < tg.MAX_ALREADY, (g["name"], already)
        assert (round(feasible, 4), round(already, 4)) == (g["feasible"], g["already"]), (
            f"{g['name']}: the planner or the scenes changed; redraw with `{tg.REDRAW}`")
        assert not (goal.stays and tg.stays_is_vacuous(goal)), g["name"]
    # filter 3 (enough scenes in every default trial's pool) is tests/test_protocol.py's check


def test_the_suite_resolves_by_name():
    assert "truth-goals" in SUITE_NAMES
    names = suite("truth-goals")
    assert names == [g["name"] for g in GOALS]
    for g in GOALS:
        it = resolve(g["name"])
        assert isinstance(it, GoalIntention) and it.name == g["name"]
        assert it.goal.key == g["key"] and it.description == g["sentence"]
        assert suite_of(g["name"]) == "truth-goals"
    others = {n for s in SUITE_NAMES if s != "truth-goals" for n in suite(s)}
    assert not set(names) & others, "a truth-goal name is also a name of another suite"  # names never printed
    assert suite_of("align") == "paper" and suite_of("dev-rainbow-row") == "dev"


def _cli(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "ACTIVEINTENT_CHECK_ONLY": "1"}
    return subprocess.run([sys.executable, "-m", "activeintent.cli", *args], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=240)


def test_bench_and_run_accept_the_suite_and_its_names(tmp_path):
    res = _cli("bench", "--suite", "truth-goals", "--env", "symbolic", "--llm", "none", "--out", str(tmp_path / "b"))
    assert res.returncode == 0, res.stdout[-1500:] + res.stderr[-1500:]
    res = _cli("run", "--method", "zero-signal", "--intention", "truth-07", "--env", "symbolic", "--llm", "none",
               "--video", "none", "--out", str(tmp_path / "r"))
    assert res.returncode == 0, res.stdout[-1500:] + res.stderr[-1500:]
    res = _cli("bench", "--suite", "truth-gaols", "--out", str(tmp_path / "c"))
    assert res.returncode == 2 and "truth-goals" in res.stdout
