"""Scene designs of bayes-* and lang-* (learners/bayes/scenes.py): ``sampled`` draws random
scenes; ``belief`` draws scenes that the belief expects to show its likely goals."""

from __future__ import annotations

import json

import numpy as np
import pytest

from activeintent.goals.language import parse_goal
from activeintent.learners.bayes.hypotheses import random_scene
from activeintent.learners.bayes.scenes import SCENE_DESIGNS
from activeintent.learners.lang.hypotheses import LangSpace
from activeintent.learners.lang.learner import LangConfig, LangLearner
from activeintent.learners.registry import LearnerContext, get_method
from activeintent.runner import build_episode, check_spec
from activeintent.spec import RunSpec

RED_ON_BLUE = "every colour:red on-the-block:blue"
OTHERS = ["form tower:any all:", "every all: in-bowl:any", "form row:any all:", "every colour:green on-table:"]


def concentrated(scenes: str, seed: int) -> LangLearner:
    """A learner whose belief holds 0.99 on "every red block is on the blue block"."""
    space = LangSpace([parse_goal(k) for k in [RED_ON_BLUE, *OTHERS]])
    learner = LangLearner("stop", rng=seed, config=LangConfig(scenes=scenes), hypotheses=space.hypotheses)
    w = np.full(len(learner.hyps), 0.01 / (len(learner.hyps) - 1))
    w[0] = 0.99
    learner.belief.log_w = np.log(w)
    return learner


def test_belief_scenes_can_show_what_the_belief_expects_sampled_ones_mostly_cannot():
    def showable(scenes: str) -> int:
        designed = [concentrated(scenes, seed).design_scene() for seed in range(8)]
        return sum({"red block", "blue block"} <= set(s.objects) for s in designed)

    assert showable("belief") == 8
    assert showable("sampled") < 8
    rng = np.random.default_rng(0)  # random scenes mostly lack one of the two
    assert sum({"red block", "blue block"} <= set(random_scene(rng).objects) for _ in range(16)) < 8


def test_belief_scenes_also_follow_a_new_scene_answer_sampled_ones_do_not():
    assert {"sampled", "belief"} <= set(SCENE_DESIGNS)  # a plug-in loaded by another test may add its own
    for method in ("lang-stop", "bayes-preference"):
        settings = get_method(method).settings
        assert get_method(method)(LearnerContext(settings=settings(scenes="belief"))).redesigns_after_new_scene
        assert not get_method(method)(LearnerContext(settings=settings())).redesigns_after_new_scene


def test_the_spec_records_which_design_ran(tmp_path):
    spec = RunSpec.from_options(method="bayes-stop", intention="stack", env="symbolic", llm="none", budget=2,
                                test_scenes=3, test_pool=0, video="none", scenes="belief")
    build_episode(spec, tmp_path).run()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["config"]["spec"]["learner"]["settings"]["scenes"] == "belief"
    with pytest.raises(ValueError, match="Unknown scene design 'clever'; valid scene designs: sampled, belief"):
        check_spec(RunSpec.from_options(scenes="clever"))
    with pytest.raises(ValueError, match="Unknown scene design"):
        LangConfig(scenes="clever")
