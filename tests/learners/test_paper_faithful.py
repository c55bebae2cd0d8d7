"""The paper's learners as the paper ran them (``--variant faithful``): free-form y through Code
as Policies, reasoning before the answer, multi-turn memory, no step leak, T = 1 draws per trial
that a warm cache replays exactly. End-to-end parts talk to a scripted OpenAI-compatible server
on loopback."""

from __future__ import annotations

import json
import os
import re

import numpy as np
import pytest
from chat_server import GOALS, PROGRAM, ChatServer, schema_name

from activeintent.act.failures import ExecutionFailure
from activeintent.learners.base import Estimate, RoundRecord
from activeintent.learners.paper.faithful import (
    FaithfulConfig,
    FaithfulMllmLearner,
    FaithfulMllmLlmLearner,
    FaithfulPreferenceLearner,
)
from activeintent.learners.paper.retrievers import (
    as_view_text,
    faithful_prompt_h,
    faithful_symbolic_retrieval,
    prompt_h,
)
from activeintent.learners.paper.structured import (
    MllmLlmLearner,
    PaperLearnerConfig,
    PaperSettings,
    failure_reason,
)
from activeintent.learners.registry import LearnerContext, get_method
from activeintent.llm.base import ImagePart
from activeintent.llm.scripted import ScriptedModel
from activeintent.records import read_rounds
from activeintent.runner import RunSpec, build_episode
from activeintent.signals.preference import PreferenceAnswer
from activeintent.signals.stop import StopAnswer
from activeintent.world import PutIn, PutOn, Scene, WorldState, describe_skill, layout
from helpers import kinematic_trajectory

SCENE = Scene(objects=["red block", "blue block", "red bowl", "green bowl"])
PLAN = [PutIn(block="red block", bowl="green bowl"), PutOn(block="blue block", target="red block")]
NO_DESIGN = FaithfulConfig(design_scenes=False, seed=11)


def require_sandbox() -> None:
    from activeintent.act.isolation import isolation_status

    status = isolation_status()
    if not status.available:
        if os.environ.get("CI"):
            pytest.fail(f"sandbox namespaces unavailable in CI: {status.detail}")
        pytest.skip(f"sandbox namespaces unavailable: {status.detail}")


def respond(messages, schema):
    title = (schema or {}).get("title", "")
    if title == "FaithfulScene":
        return {"reasoning": "bowls that match blocks", "blocks": SCENE.blocks, "bowls": SCENE.bowls}
    if title in ("FaithfulAnswer", "FaithfulPairAnswer"):
        out = {"reasoning": "the stop came early, so the first move was wrong", "preference": "matching colours"}
        if title == "FaithfulAnswer":
            out["goal"] = "tidy the blocks into bowls"
        else:
            out.update(goal_a="tidy the blocks into bowls", goal_b="build a tower", done=False)
        return out
    if title == "FaithfulRetrieval":
        return {"reasoning": "the red block went into the green bowl", "retrieved": "the person dislikes mismatched bowls"}
    raise AssertionError(f"unexpected schema {title}")


def state() -> WorldState:
    return WorldState(positions=layout(SCENE, 3))


def skill_texts(traj) -> list[str]:
    return [describe_skill(s.skill) for s in traj.steps]


# -- eq. 3 without the step leak; ε and the threshold are two numbers ------------------------------

def test_faithful_prompt_h_carries_the_time_and_the_pictures_only():
    traj = kinematic_trajectory(SCENE, 3, PLAN)  # 2 skills × 3 s
    for t in (1.5, 4.5):
        ph = faithful_prompt_h(traj, StopAnswer(stop_time=t), "tidy up", epsilon=2.0, early=2.0)
        text = as_view_text(ph, traj) + faithful_symbolic_retrieval(ph, traj, StopAnswer(stop_time=t))
        assert f"{t:.1f} seconds" in text
        assert not any(s in text for s in skill_texts(traj)) and not re.search(r"\bstep\b", text)
    # the structured variant still names the skill at the stop (kept as it was, labelled)
    structured = prompt_h(traj, StopAnswer(stop_time=4.5), "g", 2.0)
    assert "put the blue block on the red block" in structured.moments[-1].caption


def test_epsilon_and_the_early_threshold_are_separate():
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    h = StopAnswer(stop_time=2.5)
    assert faithful_prompt_h(traj, h, "g", epsilon=1.0, early=3.0).case == "early"
    late = faithful_prompt_h(traj, h, "g", epsilon=1.0, early=2.0)
    assert late.case == "late" and [m.t for m in late.moments] == [0.0, 1.5, 2.5]
    assert prompt_h(traj, h, "g", 1.0, early=3.0).case == "early"
    assert faithful_prompt_h(traj, StopAnswer(stop_time=None), "g", 2.0, 2.0).case == "none"
    nothing = kinematic_trajectory(SCENE, 3, [])
    assert "nothing moved" in faithful_prompt_h(nothing, StopAnswer(), "g", 2.0, 2.0).text


def test_a_picture_shows_the_block_in_the_gripper():
    from activeintent.learners.paper.retrievers import describe_view

    lifted = dict(layout(SCENE, 3))
    x, y, _ = lifted["red block"]
    lifted["red block"] = (x, y, 0.2)
    assert "holding the red block in the air" in describe_view(WorldState(positions=lifted))


# -- the learners --------------------------------------------------------------------------------

def test_answers_are_free_text_after_reasoning_and_sampled_with_the_trial_seed():
    model = ScriptedModel(respond=respond, accepts_images=False)
    learner = FaithfulMllmLlmLearner(model, config=NO_DESIGN)
    est = learner.estimate(SCENE, state())
    assert est.goals == ["tidy the blocks into bowls"] and est.z == "matching colours"
    assert est.why["reasoning"].startswith("the stop came early")
    request = model.calls[0]
    assert list(request.json_schema["properties"])[:3] == ["reasoning", "preference", "goal"]
    assert "pattern" not in json.dumps(request.json_schema)  # y is not forced into a phrasing
    assert request.temperature == 1.0 and request.seed == 11
    (entry,) = learner.drain_transcript()
    assert entry["variant"] == "faithful" and entry["seed"] == 11 and entry["answer"]["reasoning"]


def test_memory_keeps_earlier_rounds_and_stops_carry_no_step():
    model = ScriptedModel(respond=respond, accepts_images=False)
    learner = FaithfulMllmLlmLearner(model, config=NO_DESIGN)
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    for i, t in enumerate((4.5, None)):
        est = learner.estimate(SCENE, state())
        learner.observe(RoundRecord(index=i, scene=SCENE, estimate=est, answer=StopAnswer(stop_time=t)), [traj])
    learner.estimate(SCENE, state())
    messages = model.calls[-1].messages
    roles = [m.role for m in messages]
    assert roles == ["system", "user", "assistant", "user", "assistant", "user"]
    assert "reasoning" in messages[2].text  # its own earlier answer, reasoning included
    assert "pressed stop 4.5 seconds" in messages[3].text and "watched" not in messages[3].text
    assert "to the end" in messages[5].text
    every = "\n".join(m.text for c in model.calls for m in c.messages)
    assert not any(s in every for s in skill_texts(traj)) and not re.search(r"\bstep \d", every)


def test_the_mllm_sees_earlier_rounds_images():
    model = ScriptedModel(respond=respond, accepts_images=True)
    learner = FaithfulMllmLearner(model, NO_DESIGN)
    assert learner.retriever == "vision"
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    traj.renderer = lambda tr, t, size: np.full((*size, 3), int(t * 10), np.uint8)
    for i, t in enumerate((4.5, 1.0)):
        est = learner.estimate(SCENE, state())
        learner.observe(RoundRecord(index=i, scene=SCENE, estimate=est, answer=StopAnswer(stop_time=t)), [traj])
    learner.estimate(SCENE, state())
    images = [sum(isinstance(p, ImagePart) for p in m.content) if not isinstance(m.content, str) else 0
              for m in model.calls[-1].messages]
    assert sum(images) == 3 + 2  # the late stop's I_0, I_b, I_s stay; the early stop adds I_0, I_s
    # an env that cannot draw (--env symbolic): the pictures are described instead, and labelled so
    traj.renderer = None
    est = learner.estimate(SCENE, state())
    learner.observe(RoundRecord(index=2, scene=SCENE, estimate=est, answer=StopAnswer(stop_time=4.5)), [traj])
    assert learner.retriever == "symbolic" and "[picture I_b]" in learner.pending[-1].text


def test_the_vision_retriever_keeps_its_own_conversation(monkeypatch):
    from activeintent.world.trajectory import Trajectory

    monkeypatch.setattr(Trajectory, "frame", lambda self, t, size=(240, 240): np.zeros((*size, 3), np.uint8))
    llm, vlm = ScriptedModel(respond=respond, accepts_images=False), ScriptedModel(respond=respond)
    learner = FaithfulMllmLlmLearner(llm, vlm, retriever="vision", config=NO_DESIGN)
    traj = kinematic_trajectory(SCENE, 3, PLAN)
    est = Estimate(z="p", goals=["tidy up"])
    for i, t in enumerate((4.5, 1.0)):
        r = learner.observe(RoundRecord(index=i, scene=SCENE, estimate=est, answer=StopAnswer(stop_time=t)), [traj])
        assert r == "the person dislikes mismatched bowls"
    second = vlm.calls[-1]
    assert [m.role for m in second.messages] == ["system", "user", "assistant", "user"]
    assert sum(isinstance(p, ImagePart) for m in second.messages if not isinstance(m.content, str)
               for p in m.content) == 5
    assert second.temperature == 0.0  # the original asked its vision model at T = 0


def test_preference_feedback_and_done():
    model = ScriptedModel(respond=respond, accepts_images=False)
    learner = FaithfulPreferenceLearner(model, NO_DESIGN)
    est = learner.estimate(SCENE, state())
    assert est.goals == ["tidy the blocks into bowls", "build a tower"] and est.done is False
    assert "done" in model.calls[0].json_schema["properties"]
    learner.observe(RoundRecord(index=0, scene=SCENE, estimate=est, answer=PreferenceAnswer(choice="B")), [])
    learner.estimate(SCENE, state())
    assert 'preferred goal B ("build a tower") over goal A' in model.calls[-1].messages[-1].text


def test_an_unusable_answer_does_not_end_the_round():
    model = ScriptedModel(respond=lambda m, s: "no JSON here", accepts_images=False, max_repairs=1)
    learner = FaithfulMllmLlmLearner(model, config=NO_DESIGN)
    est = learner.estimate(SCENE, state())
    assert est.goals == [""] and "unusable" in est.why
    assert len(learner.conversation) == 1  # nothing half-done joins the memory
    assert "unusable" in learner.drain_transcript()[0]


def test_failure_text_is_said_once_and_test_scene_failures_stay_out_of_the_memory():
    feedback = ExecutionFailure(stage="program", message="NameError: x (line 2)").feedback_text()
    model = ScriptedModel(respond=respond, accepts_images=False)
    learner = FaithfulMllmLlmLearner(model, config=NO_DESIGN)
    learner.estimate(SCENE, state())
    learner.execution_failed("tidy the blocks into bowls", feedback)
    learner.estimate(SCENE, state())
    retry = model.calls[-1].messages[-1].text
    assert retry.count("simpler goal") == 1 and "program failed: NameError: x (line 2)" in retry
    # a failure on a test scene is retried there, and never reaches the learning conversation
    learner.final(SCENE, state())
    learner.execution_failed("tidy the blocks into bowls", feedback)
    learner.final(SCENE, state())
    assert model.calls[-1].messages[-1].text.count("simpler goal") == 1
    turns = len(learner.conversation)
    learner.estimate(SCENE, state())
    assert "simpler goal" not in model.calls[-1].messages[-1].text and len(learner.conversation) == turns + 2
    # the structured variant's note no longer repeats the request either
    structured = MllmLlmLearner(ScriptedModel(respond=respond), config=PaperLearnerConfig(design_scenes=False))
    structured.execution_failed("g", feedback)
    assert structured.notes[0].count("simpler goal") == 1 and failure_reason("slipped") == "slipped"


def test_variant_is_chosen_by_the_context():
    model = ScriptedModel(respond=respond)
    assert get_method("mllm")(LearnerContext(llm=model)).variant == "faithful"
    assert get_method("mllm")(LearnerContext(llm=model, settings=PaperSettings(variant="structured"))).variant == "structured"
    with pytest.raises(ValueError, match="valid variants: faithful, structured"):
        PaperSettings(variant="fancy")  # refused with the spec, before any learner is built


# -- end to end, through a real HTTP server ------------------------------------------------------

def options(server: ChatServer, cache, **extra) -> RunSpec:
    return RunSpec.from_options(method="mllm-llm", intention="color-mismatch", env="symbolic", user="exact", llm="openai:fake",
                      base_url=server.base_url, cache=str(cache), executor="cap", budget=3, test_scenes=2,
                      video="none", **extra)


def comparable(rounds: list[dict]) -> list[dict]:
    """Round records without wall-clock figures."""
    out = []
    for r in rounds:
        r = dict(r)
        r.pop("timing")
        r["calls"] = [{k: v for k, v in c.items() if k != "s"} for c in r["calls"]]
        out.append(r)
    return out


def test_mllm_llm_sends_free_form_y_to_code_as_policies(tmp_path, monkeypatch):
    require_sandbox()
    monkeypatch.setenv("OPENAI_API_KEY", "test")
    with ChatServer() as server:
        result = build_episode(options(server, tmp_path / "cache.sqlite"), tmp_path / "ep").run()
    assert result.error is None and result.variant == "faithful"
    rounds = read_rounds(tmp_path / "ep" / "rounds.jsonl")
    assert len(rounds) == 3 and all(r["variant"] == "faithful" for r in rounds)
    for r in rounds:
        (goal,) = r["goals"]
        assert goal in GOALS  # free-form, not the canonical phrasing
        cap = [c for c in r["calls"] if c["template"] == "executor_cap"]
        assert cap and cap[-1]["instruction"] == goal and cap[-1]["program"] == PROGRAM.strip("\n")
        assert cap[-1]["plan"] == r["plans"][0] and r["plans"][0]
        model_call = next(c for c in r["calls"] if c["template"] == "faithful_eq56")
        assert model_call["answer"]["reasoning"].startswith("draw ")
    stops = [r for r in rounds if r["answer"]["stop_time"] is not None]
    assert stops  # the hidden intention (mismatching bowls) objects to the first move
    skills = {s for r in rounds for p in r["plans"] for s in p.split(", then ")}
    prompts = [c["prompt"] for r in rounds for c in r["calls"] if "prompt" in c]
    assert prompts
    for p in prompts:
        assert not any(s in p for s in skills), "a skill of the plan reached a prompt"
        assert not re.search(r"\bstep \d|while it was doing", p)
    # CaP was asked for every y, at T = 0; the learner's calls sampled at T = 1
    bodies = server.requests
    assert sum(schema_name(b) is None for b in bodies) >= len(rounds)
    assert {b["temperature"] for b in bodies if schema_name(b) is None} == {0.0}
    assert {b["temperature"] for b in bodies if schema_name(b) in ("FaithfulScene", "FaithfulAnswer")} == {1.0}


def test_k_rounds_run_whatever_the_model_says(tmp_path, monkeypatch):
    require_sandbox()
    monkeypatch.setenv("OPENAI_API_KEY", "test")
    with ChatServer(garbage_for=set(range(4, 40))) as server:  # after the first few calls: no JSON at all
        result = build_episode(options(server, tmp_path / "cache.sqlite", cache_mode="off"), tmp_path / "ep").run()
    assert result.error is None and result.rounds_used == result.signals_used == 3
    assert any("unusable" in c for r in read_rounds(tmp_path / "ep" / "rounds.jsonl") for c in r["calls"])


def test_trials_are_independent_draws_and_replay_exactly(tmp_path, monkeypatch):
    require_sandbox()
    from activeintent.bench.work import WorkItem, run_item

    monkeypatch.setenv("OPENAI_API_KEY", "test")
    cache = tmp_path / "cache.sqlite"

    def trial(t: int, out, mode: str, server: ChatServer) -> list[dict]:
        record = run_item(WorkItem(method="mllm-llm", intention="color-mismatch", trial=t),
                          options(server, cache, cache_mode=mode), 0, str(out), True)
        assert record["error"] is None, record.get("traceback")
        return read_rounds(out / "episodes" / "mllm-llm" / "color-mismatch" / f"trial{t}" / "rounds.jsonl")

    with ChatServer() as server:
        first = [trial(t, tmp_path / "record", "record", server) for t in (0, 1)]  # trial 1 meets a warm cache
        asked = len(server.requests)
        replayed = [trial(t, tmp_path / "replay", "replay", server) for t in (0, 1)]
        assert len(server.requests) == asked  # nothing new was asked: both came from the cache
    seeds = [first[t][0]["calls"][0]["seed"] for t in (0, 1)]
    assert seeds[0] != seeds[1]
    # the very first request (the scene design) reads the same in both trials, but is drawn anew
    assert first[0][0]["calls"][0]["prompt"] == first[1][0]["calls"][0]["prompt"]
    assert first[0][0]["calls"][0]["answer"] != first[1][0]["calls"][0]["answer"]
    assert comparable(replayed[0]) == comparable(first[0]) and comparable(replayed[1]) == comparable(first[1])


def test_bench_preset_table1_runs_the_papers_methods_beside_its_rows(tmp_path, monkeypatch):
    require_sandbox()
    from typer.testing import CliRunner

    from activeintent.cli import app
    from activeintent.results import read_results

    monkeypatch.setenv("OPENAI_API_KEY", "test")
    runner = CliRunner()
    refused = runner.invoke(app, ["bench", "--preset", "table1", "--budget", "3", "--out", str(tmp_path / "x")])
    assert refused.exit_code == 2 and "K = 5" in refused.output
    with ChatServer() as server:
        res = runner.invoke(app, ["bench", "--no-oracle", "--preset", "table1", "--trials", "1", "--test-scenes", "1", "--env", "symbolic",
                                  "--user", "exact", "--llm", "openai:fake", "--base-url", server.base_url,
                                  "--executor", "cap", "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "b")])
    assert res.exit_code == 0, res.output
    records = read_results(tmp_path / "b" / "results.jsonl")
    assert {(r["method"], r["intention"]) for r in records} == {
        (m, i) for m in ("preference", "mllm", "mllm-llm") for i in ("align", "stack", "color-match", "color-mismatch")}
    assert all(r["error"] is None and r["budget"] == 5 and r["signals_used"] == 5 and r["variant"] == "faithful"
               for r in records)
    report = (tmp_path / "b" / "report.md").read_text()
    assert "| mllm-llm (paper) | gpt-4-vision-preview (r) + gpt-4-1106-preview (z, y) |" in report
    assert "| mllm-llm (ours) | symbolic retriever (r) + openai:fake (z, y) | faithful |" in report
    assert "| preference (ours) | openai:fake | faithful |" in report and "variant = `faithful`" in report


def test_resuming_a_folder_made_before_variants_existed(tmp_path):
    from activeintent.bench.runner import _check_same_settings
    from activeintent.bench.work import BenchConfig

    old = BenchConfig(methods=["bayes-stop"], intentions=["stack"], run=RunSpec.from_options(video="none"))
    data = json.loads(old.model_dump_json())
    data["run"] = {k: v for k, v in old.run.options().items() if k != "plugin"}  # format 1: flat option names
    (tmp_path / "bench.json").write_text(json.dumps(data))
    _check_same_settings(old, tmp_path / "bench.json")  # Bayesian methods have no variant: same settings
    data["methods"] = ["mllm"]
    (tmp_path / "bench.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="other settings"):  # the old folder ran the structured variant
        _check_same_settings(old.model_copy(update={"methods": ["mllm"]}), tmp_path / "bench.json")
    structured = old.model_copy(update={"methods": ["mllm"], "run": RunSpec.from_options(video="none", variant="structured")})
    _check_same_settings(structured, tmp_path / "bench.json")


def test_the_scene_choice_is_a_turn_of_the_conversation():
    model = ScriptedModel(respond=respond, accepts_images=False)
    learner = FaithfulMllmLlmLearner(model, config=FaithfulConfig(seed=1))
    assert learner.design_scene() == SCENE
    learner.estimate(SCENE, state())
    assert [m.role for m in model.calls[-1].messages] == ["system", "user", "assistant", "user"]
    too_many = ScriptedModel([{"reasoning": "r", "blocks": ["red block", "blue block", "green block"],
                               "bowls": ["red bowl", "blue bowl", "green bowl"]}], accepts_images=False)
    learner = FaithfulMllmLlmLearner(too_many, config=FaithfulConfig(seed=1))
    assert learner.design_scene() is None  # 6 objects: the episode samples one
    assert "at most 5" in learner.drain_transcript()[-1]["unusable"]


def test_identical_showcases_are_asked_again():
    """Goals A and B the same (up to case and a full stop): the learner asks again in the same
    conversation, and the round shows two different goals."""
    same = {"reasoning": "r", "preference": "matching colours", "goal_a": "Put the red block in the red bowl.",
            "goal_b": "put the red block in the red bowl", "done": False}
    differ = {**same, "goal_b": "put the blue block on the red block"}
    model = ScriptedModel([same, differ], accepts_images=False)
    learner = FaithfulPreferenceLearner(model, NO_DESIGN)
    est = learner.estimate(SCENE, state())
    assert est.goals == ["Put the red block in the red bowl.", "put the blue block on the red block"]
    assert est.why["reasked_same_goals"] == 1 and len(model.calls) == 2
    assert "Goals A and B are the same" in model.calls[1].messages[-1].text
    assert [m.role for m in model.calls[1].messages] == ["system", "user", "assistant", "user"]


def test_identical_showcases_are_asked_again_at_most_twice():
    same = {"reasoning": "r", "preference": "p", "goal_a": "stack them", "goal_b": "stack them", "done": False}
    model = ScriptedModel(respond=lambda m, s: same, accepts_images=False)
    est = FaithfulPreferenceLearner(model, NO_DESIGN).estimate(SCENE, state())
    assert est.goals == ["stack them", "stack them"] and len(model.calls) == 3


def test_a_history_longer_than_the_context_is_summarised_oldest_first():
    """A model whose context holds only a few messages (ContextOverflowError, as the embedded
    backend raises it): the learner drops its oldest exchanges into a summary in the system turn
    (the person's answers and its own preference and goals kept) and every round and test scene
    still gets an answer; before, the episode ended with a model error."""
    from activeintent.llm.base import ContextOverflowError

    def small_context(messages, schema):
        if len(messages) > 5:
            raise ContextOverflowError("the prompt leaves no room for an answer")
        return respond(messages, schema)

    model = ScriptedModel(respond=small_context, accepts_images=False)
    learner = FaithfulPreferenceLearner(model, NO_DESIGN)
    for i, choice in enumerate("ABA"):
        est = learner.estimate(SCENE, state())
        assert est.goals == ["tidy the blocks into bowls", "build a tower"]
        learner.observe(RoundRecord(index=i, scene=SCENE, estimate=est, answer=PreferenceAnswer(choice=choice)), [])
    assert learner.final(SCENE, state()).goals == ["tidy the blocks into bowls"]
    system = model.calls[-1].messages[0].text
    assert "Earlier rounds, in short" in system
    assert 'preferred goal A ("tidy the blocks into bowls")' in system and "“matching colours”" in system
    assert "goal b: “build a tower”" in system
    assert len(model.calls[-1].messages) <= 5 and learner.stats()["summarised"] >= 2


def test_showcases_that_become_one_motion_are_asked_again():
    """Goals A and B worded differently but planned to the same motion: the episode tells the
    learner and asks once more (max_goal_retries = 1); the round shows two different motions."""
    from types import SimpleNamespace

    from activeintent.episode import Episode

    first = {"reasoning": "r", "preference": "p", "goal_a": "tidy the red one", "goal_b": "red block to its bowl",
             "done": False}
    second = {**first, "goal_a": "red block in the red bowl", "goal_b": "red block on the blue block"}
    model = ScriptedModel([first, second], accepts_images=False)
    learner = FaithfulPreferenceLearner(model, NO_DESIGN)
    same = PutIn(block="red block", bowl="red bowl")
    plans = {"tidy the red one": same, "red block to its bowl": same, "red block in the red bowl": same,
             "red block on the blue block": PutOn(block="red block", target="blue block")}
    episode = SimpleNamespace(clock=SimpleNamespace(timed=lambda name, f, *a: f(*a)),
                              protocol=SimpleNamespace(max_goal_retries=1), learner=learner,
                              _plan=lambda goal, st: ([plans[goal]], None))
    est, got, failures = Episode.ground(episode, learner.estimate, SCENE, state())
    assert est.goals == ["red block in the red bowl", "red block on the blue block"] and got[0] != got[1]
    assert len(model.calls) == 2 and "made the robot do the same thing" in model.calls[1].messages[-1].text
    assert learner.stats()["alike_reasks"] == 1 and failures == [None, None]

    # a learner that does not take it back (the default) is not asked again
    model = ScriptedModel([first, second], accepts_images=False)
    learner = FaithfulPreferenceLearner(model, NO_DESIGN)
    learner.showcases_alike = lambda goals: False
    episode.learner = learner
    est, got, _ = Episode.ground(episode, learner.estimate, SCENE, state())
    assert est.goals == ["tidy the red one", "red block to its bowl"] and got[0] == got[1] and len(model.calls) == 1
