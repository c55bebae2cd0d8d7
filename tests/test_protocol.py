"""The test pool is large enough: with the default sizes every intention of every suite can be
shown in at least 5 of the test scenes scored at k = K, in every trial a default bench runs."""

from __future__ import annotations

import pytest

from activeintent.protocol import (
    DEFAULT_TEST_POOL,
    DEFAULT_TEST_SCENES,
    draw_test_scenes,
    trial_seeds,
)
from activeintent.spec import EpisodeSeeds
from activeintent.suites import SUITE_NAMES, resolve, suite

MIN_SCORED = 5


def pool(trial: int, bench_seed: int = 0) -> list:
    """The scenes an episode of this trial is scored on (its test seed, the default sizes)."""
    _, test_seed = trial_seeds(bench_seed, "any intention", trial)
    scenes = draw_test_scenes(EpisodeSeeds.from_seed(0, test_seed).test, DEFAULT_TEST_SCENES + DEFAULT_TEST_POOL)
    return [s for s, _ in scenes]


# truth-goals: 50 planner-judged goals × 20 pools take about 100 s (suites/truth_goals.py's draw
# keeps only goals that pass this check, so it fails only if the planner or the scenes change)
@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n == "truth-goals" else n
                                  for n in SUITE_NAMES])
def test_every_intention_is_scorable_on_enough_scenes_in_every_default_trial(name):
    intentions = [resolve(n) for n in suite(name)]
    for trial in range(20):  # bench's default trial count
        scenes = pool(trial)
        fewest = min(sum(bool(it.feasible(s)) for s in scenes) for it in intentions)
        assert fewest >= MIN_SCORED, f"suite {name}, trial {trial}: an intention is feasible in {fewest} scenes"


def test_the_pool_is_the_episodes_own(tmp_path):
    from activeintent.runner import RunSpec, build_episode

    _, test_seed = trial_seeds(0, "any intention", 3)
    r = build_episode(RunSpec.from_options(method="zero-signal", intention="two-towers", env="symbolic", llm="none",
                                 video="none", budget=1, seed=1, test_seed=test_seed)).run()
    assert [t.scene for t in r.tests] == [list(s.objects) for s in pool(3)]
    assert r.test_scored == sum(bool(resolve("two-towers").feasible(s)) for s in pool(3)) >= MIN_SCORED
