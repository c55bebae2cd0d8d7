"""The run specification: flat option names map to one section each and back, bad values are
refused naming the option as the command line spells it, and the seed is split once."""

from __future__ import annotations

import pytest

from activeintent.spec import OPTIONS, EpisodeSeeds, RunSpec


def test_every_option_lands_in_its_section_and_reads_back():
    changed = {"method": "lang-stop", "intention": "stack", "intention_file": None, "plugins": ["x.py"],
               "budget": 7, "seed": 3, "test_seed": 9, "test_scenes": 4, "test_pool": 5, "env": "symbolic",
               "user": "paper", "new_scene": "free", "prior": "uniform", "scenes": "belief", "language": 1, "llm": "none",
               "vlm": "openai:v",
               "base_url": "http://h", "cache": "c.sqlite", "cache_mode": "off", "executor": "parse",
               "retriever": "vision", "epsilon": 1.5, "early_threshold": 0.5, "variant": "structured",
               "design_scenes": False, "video": "all", "curve": False, "stop_when_done": True}
    assert set(changed) == set(OPTIONS)  # every option is exercised
    spec = RunSpec.from_options(**changed)
    assert spec.options() == changed
    assert (spec.learner.method, spec.env.name, spec.user.preset, spec.protocol.budget, spec.models.vlm) == (
        "lang-stop", "symbolic", "paper", 7, "openai:v")
    assert RunSpec.model_validate(spec.model_dump()) == spec  # the nested form is its own format


def test_defaults_are_the_command_lines():
    spec = RunSpec()
    assert spec.protocol.video == "final" and spec.models.llm == "embedded" and spec.env.name == "pybullet"
    assert RunSpec.from_options() == spec


def test_a_bad_value_names_the_option_and_an_unknown_option_lists_the_valid_ones():
    with pytest.raises(ValueError, match="--budget: "):
        RunSpec.from_options(budget=-1)
    with pytest.raises(ValueError, match="--early-threshold: "):
        RunSpec.from_options(early_threshold=-2)
    with pytest.raises(ValueError, match="valid variants: faithful, structured"):
        RunSpec.from_options(variant="fancy")
    with pytest.raises(ValueError, match="unknown option.*rounds.*valid options: method"):
        RunSpec.from_options(rounds=3)


def test_with_options_changes_only_what_it_names():
    base = RunSpec.from_options(env="symbolic", llm="none", budget=4)
    moved = base.with_options(seed=11, method="zero-signal")
    assert moved.protocol.seed == 11 and moved.learner.method == "zero-signal"
    assert {k: v for k, v in moved.options().items() if k not in ("seed", "method")} == {
        k: v for k, v in base.options().items() if k not in ("seed", "method")}


def test_the_seed_is_split_once_into_distinct_named_streams():
    spec = RunSpec.from_options(seed=5, test_seed=8)
    seeds = spec.seeds
    assert seeds == EpisodeSeeds.from_seed(5, 8) and seeds is spec.protocol.seeds  # cached: one split
    assert len({seeds.scenes, seeds.layouts, seeds.user, seeds.learner, seeds.test}) == 5
    assert RunSpec.from_options(seed=5, test_seed=9).seeds.learner == seeds.learner  # the test seed moves only the tests
    assert RunSpec.from_options(seed=5, test_seed=9).seeds.test != seeds.test
