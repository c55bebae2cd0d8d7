"""The paper's learners condition on what the equations say (eq. 1–6), checked with a scripted model."""

from __future__ import annotations

import re

import pytest

from activeintent.learners import prompts
from activeintent.learners.base import Estimate, RoundRecord
from activeintent.learners.paper.retrievers import as_text, prompt_h
from activeintent.learners.paper.schemas import goal_pattern, goals_schema
from activeintent.learners.paper.structured import (
    MllmLearner,
    MllmLlmLearner,
    PaperLearnerConfig,
    PreferenceLearner,
)
from activeintent.llm.base import ImagePart
from activeintent.llm.scripted import ScriptedModel
from activeintent.signals.preference import PreferenceAnswer
from activeintent.signals.stop import StopAnswer
from activeintent.world import PutIn, PutNextTo, PutOn, Scene, WorldState, describe_plan, layout
from helpers import kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "red bowl", "green bowl"])
PLAN = [PutIn(block="red block", bowl="green bowl"), PutOn(block="blue block", target="red block")]


def responder(messages, schema):
    title = (schema or {}).get("title", "")
    if title == "IntentionAnswer":
        return {"preference": "The user wants each block in the bowl of its own colour.", "done": False}
    if title == "GoalsAnswer":
        fields = list(schema["properties"])
        goals = ["put the red block in the red bowl", "put the red block in the green bowl, then put the blue block on the red block"]
        return dict(zip(fields, goals, strict=False))
    if title == "RetrievalAnswer":
        return {"retrieved": "The robot put the red block into the green bowl, which the user did not want."}
    if title == "SceneChoice":
        return {"objects": ["red block", "blue block", "red bowl", "green bowl"]}
    raise AssertionError(f"unexpected schema {title}")


def state() -> WorldState:
    return WorldState(positions=layout(SCENE, 3))


def test_every_template_renders_and_has_a_version():
    task = prompts.render("x_task")
    assert "put the red block in the blue bowl" in task
    for name in ("eq1_intention", "eq5_intention"):
        assert "HISTORY" in prompts.render(name, task=task, history="HISTORY")
    assert set(prompts.sections("eq3_prompt_h")) == {"x_n", "x_0", "x_b", "x_s"}
    assert prompts.version("eq1_intention") != prompts.version("eq5_intention")
    with pytest.raises(KeyError):
        prompts.render("eq1_intention", task=task)  # a missing value is an error, not an empty prompt


def test_goal_pattern_accepts_canonical_plans_and_rejects_unknown_objects():
    pattern = re.compile(goal_pattern(SCENE))
    assert pattern.match(describe_plan(PLAN))
    assert pattern.match(describe_plan([PutNextTo(block="red block", target="green bowl", side="left")]))
    assert not pattern.match("put the purple block in the red bowl")
    assert not pattern.match("put the red bowl in the red block")
    schema = goals_schema(SCENE, 2)
    assert set(schema.model_fields) == {"goal_a", "goal_b"}


def test_prompt_h_has_the_three_cases_of_eq3():
    traj = kinematic_trajectory(SCENE, 3, PLAN)  # 2 skills × 3 s
    eps = 2.0
    none = prompt_h(traj, StopAnswer(stop_time=None), "g", eps)
    early = prompt_h(traj, StopAnswer(stop_time=1.5), "g", eps)
    late = prompt_h(traj, StopAnswer(stop_time=4.5), "g", eps)
    assert none.case == "none" and none.image_labels == []
    assert early.case == "early" and early.image_labels == ["I_0", "I_s"]
    assert late.case == "late" and late.image_labels == ["I_0", "I_b", "I_s"]
    assert [m.t for m in late.moments] == [0.0, 2.5, 4.5]
    text = as_text(late, traj)
    assert "[I_b]" in text and "put the blue block on the red block" in text


def test_preference_learner_conditions_on_z_y_h_history():
    model = ScriptedModel(respond=responder)
    learner = PreferenceLearner(model, PaperLearnerConfig(design_scenes=False))
    est = learner.estimate(SCENE, state())
    assert len(est.goals) == 2 and est.goals[0] != est.goals[1]
    first_prompt = model.calls[0].messages[-1].text
    assert "none yet" in first_prompt
    record = RoundRecord(index=0, scene=SCENE, estimate=est, answer=PreferenceAnswer(choice="A"))
    assert learner.observe(record, []) is None
    learner.estimate(SCENE, state())
    eq1 = model.calls[2].messages[-1].text  # eq. 1 for round 2
    assert est.z in eq1 and est.goals[0] in eq1 and est.goals[1] in eq1
    assert "preferred goal A" in eq1
    eq2 = model.calls[3].messages[-1].text  # eq. 2 conditions on z_{i+1} and the history
    assert "Estimated preference z:" in eq2 and "preferred goal A" in eq2


def test_mllm_llm_learner_retrieves_r_and_conditions_on_it():
    model = ScriptedModel(respond=responder)
    learner = MllmLlmLearner(model, retriever="symbolic", config=PaperLearnerConfig(design_scenes=False))
    est = learner.estimate(SCENE, state())
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    h = StopAnswer(stop_time=1.5)
    r = learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, answer=h), [traj])
    assert "put the red block in the green bowl" in r
    learner.estimate(SCENE, state())
    eq5 = model.calls[-2].messages[-1].text
    assert "r_1:" in eq5 and r in eq5 and "stopped the robot at t = 1.50 s" in eq5 and est.goals[0] in eq5


def test_vision_retriever_sends_the_eq3_images(monkeypatch):
    import numpy as np

    from activeintent.world.trajectory import Trajectory

    monkeypatch.setattr(Trajectory, "frame", lambda self, t, size=(240, 240): np.full((*size, 3), int(t * 10), np.uint8))
    llm, vlm = ScriptedModel(respond=responder), ScriptedModel(respond=responder)
    learner = MllmLlmLearner(llm, vlm, retriever="vision", config=PaperLearnerConfig(design_scenes=False))
    est = Estimate(z="p", goals=[describe_plan(PLAN)])
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    for stop, n_images in ((None, 0), (1.0, 2), (4.0, 3)):
        h = StopAnswer(stop_time=stop)
        learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, answer=h), [traj])
        parts = vlm.calls[-1].messages[-1].content
        assert sum(isinstance(p, ImagePart) for p in parts) == n_images  # h = None: x_n, text only
    assert len(vlm.calls) == 3


def test_mllm_learner_sees_the_images_itself(monkeypatch):
    import numpy as np

    from activeintent.world.trajectory import Trajectory

    monkeypatch.setattr(Trajectory, "frame", lambda self, t, size=(240, 240): np.zeros((*size, 3), np.uint8))
    model = ScriptedModel(respond=responder, accepts_images=True)
    learner = MllmLearner(model, PaperLearnerConfig(design_scenes=False))
    assert learner.retriever == "vision"
    est = learner.estimate(SCENE, state())
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, answer=StopAnswer(stop_time=4.0)), [traj])
    learner.estimate(SCENE, state())
    parts = model.calls[-2].messages[-1].content
    assert sum(isinstance(p, ImagePart) for p in parts) == 3


def test_scene_design_falls_back_on_unusable_choice():
    model = ScriptedModel([{"objects": ["red bowl", "blue bowl", "green bowl"]}])
    learner = PreferenceLearner(model)

    assert learner.design_scene() is None  # no blocks: unusable
    assert "unusable" in learner.drain_transcript()[-1]


def test_the_skill_at_the_stop_comes_from_the_trajectory_not_the_answer():
    # a person's stop is only a time: the retriever finds the step being executed itself
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    early = as_text(prompt_h(traj, StopAnswer(stop_time=1.5), "g", 2.0), traj)
    late = as_text(prompt_h(traj, StopAnswer(stop_time=4.5), "g", 2.0), traj)
    assert "put the red block in the green bowl" in early and "put the blue block on the red block" not in early
    assert "put the blue block on the red block" in late


def test_stop_learner_takes_a_new_scene_answer_without_retrieving():
    model = ScriptedModel(respond=responder)
    learner = MllmLlmLearner(model, retriever="symbolic", config=PaperLearnerConfig(design_scenes=False))
    est = learner.estimate(SCENE, state())
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    r = learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, answer=StopAnswer(new_scene=True)), [traj])
    assert r is None
    learner.estimate(SCENE, state())
    eq5 = model.calls[-2].messages[-1].text
    assert "new scene" in eq5 and "r_1:" not in eq5


def test_symbolic_retrieval_does_not_read_a_failed_execution_as_approval():
    from activeintent.learners.paper.retrievers import symbolic_retrieval

    nothing = kinematic_trajectory(SCENE, 3, [])
    ph = prompt_h(nothing, StopAnswer(), "g", 2.0)
    assert "nothing moved" in symbolic_retrieval(ph, nothing, StopAnswer())
    moved = kinematic_trajectory(SCENE, 3, PLAN)
    watched = symbolic_retrieval(prompt_h(moved, StopAnswer(), "g", 2.0), moved, StopAnswer())
    assert "watched the whole execution" in watched


def test_vision_retriever_needs_a_model_that_sees_images():
    from activeintent.llm.base import ModelError

    blind = ScriptedModel(respond=responder, accepts_images=False)
    with pytest.raises(ModelError, match="accepts no images"):
        MllmLlmLearner(blind, retriever="vision")
