"""The run specification: option names map to one section each (or to the learner's settings)
and back, bad values are refused naming the option as the command line spells it, and the seed
is split once."""

from __future__ import annotations

import pytest

from activeintent.runner import check_spec
from activeintent.spec import EpisodeSeeds, RunSpec, option_fields


def test_every_option_lands_in_its_section_and_reads_back():
    changed = {"method": "lang-stop", "intention": "stack", "intention_file": None, "plugin": ["x.py"],
               "budget": 7, "seed": 3, "test_seed": 9, "test_scenes": 4, "test_pool": 5, "env": "symbolic",
               "user": "paper", "new_scene": "free", "llm": "none", "vlm": "openai:v",
               "base_url": "http://h", "cache": "c.sqlite", "cache_mode": "off", "executor": "parse",
               "video": "all", "video_fps": 5, "curve": False, "stop_when_done": True, "max_goal_retries": 2}
    assert set(changed) == set(option_fields())  # every section's option is exercised
    settings = {"prior": "uniform", "scenes": "belief", "language": 1}
    spec = RunSpec.from_options(**changed, **settings)
    assert spec.options() == {**changed, **settings}
    assert (spec.learner.method, spec.env.name, spec.user.preset, spec.protocol.budget, spec.models.vlm) == (
        "lang-stop", "symbolic", "paper", 7, "openai:v")
    assert spec.learner.settings == settings  # not a section's field: the method's setting
    assert RunSpec.model_validate(spec.model_dump()) == spec  # the nested form is its own format


def test_defaults_are_the_command_lines():
    spec = RunSpec()
    assert spec.protocol.video == "final" and spec.models.llm == "embedded" and spec.env.name == "pybullet"
    assert RunSpec.from_options() == spec and spec.learner.settings == {}


def test_a_bad_value_names_the_option_and_a_setting_the_method_lacks_lists_its_settings():
    with pytest.raises(ValueError, match="--budget: "):
        RunSpec.from_options(budget=-1)
    with pytest.raises(ValueError, match="--early-threshold: "):
        check_spec(RunSpec.from_options(method="mllm", early_threshold=-2))
    with pytest.raises(ValueError, match="valid variants: faithful, structured"):
        check_spec(RunSpec.from_options(method="mllm", variant="fancy"))
    with pytest.raises(ValueError, match="--rounds: bayes-stop has no such setting .its settings: --prior, --scenes"):
        check_spec(RunSpec.from_options(method="bayes-stop", rounds=3, llm="none"))


def test_a_checked_spec_holds_the_methods_settings_whole():
    spec = check_spec(RunSpec.from_options(method="mllm-llm", epsilon=1.5, llm="openai:m"))
    assert spec.learner.settings == {"variant": "faithful", "retriever": "symbolic", "design_scenes": True,
                                     "epsilon": 1.5, "early_threshold": 2.0}
    assert check_spec(RunSpec.from_options(method="reward-stop", llm="none")).learner.settings == {}


def test_with_options_changes_only_what_it_names():
    base = RunSpec.from_options(env="symbolic", llm="none", budget=4, prior="uniform")
    moved = base.with_options(seed=11, method="zero-signal")
    assert moved.protocol.seed == 11 and moved.learner.method == "zero-signal"
    assert {k: v for k, v in moved.options().items() if k not in ("seed", "method")} == {
        k: v for k, v in base.options().items() if k not in ("seed", "method")}
    assert base.with_options(prior=None).learner.settings == {}  # None: not given, the method's own


def test_the_seed_is_split_once_into_distinct_named_streams():
    spec = RunSpec.from_options(seed=5, test_seed=8)
    seeds = spec.seeds
    assert seeds == EpisodeSeeds.from_seed(5, 8) and seeds is spec.protocol.seeds  # cached: one split
    assert len({seeds.scenes, seeds.layouts, seeds.user, seeds.learner, seeds.test}) == 5
    assert RunSpec.from_options(seed=5, test_seed=9).seeds.learner == seeds.learner  # the test seed moves only the tests
    assert RunSpec.from_options(seed=5, test_seed=9).seeds.test != seeds.test
