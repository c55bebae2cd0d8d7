"""The structured-plan executor, the executor factory and the act-bench command."""

from __future__ import annotations

import json

import pytest
import typer
from act_helpers import require_namespaces
from pydantic import ValidationError
from typer.testing import CliRunner

from activeintent.act.executors import make_executor
from activeintent.act.failures import ExecutionFailure
from activeintent.act.plan import PlanExecutor, plan_schema
from activeintent.cli.act_bench import register
from activeintent.llm.scripted import ScriptedModel
from activeintent.world import PutAt, PutIn, PutNextTo, PutOn, Scene, WorldState, layout


def test_schema_enums_are_the_scene_objects(state):
    schema = plan_schema(state).model_json_schema()
    defs = schema["$defs"]
    assert defs["PutInStep"]["properties"]["block"]["enum"] == state.blocks
    assert defs["PutInStep"]["properties"]["bowl"]["enum"] == state.bowls
    assert defs["PutOnStep"]["properties"]["target"]["enum"] == state.blocks
    assert defs["PutNextToStep"]["properties"]["target"]["enum"] == state.names
    with pytest.raises(ValidationError):
        plan_schema(state).model_validate({"steps": [{"skill": "put_in", "block": "purple block", "bowl": "red bowl"}]})
    with pytest.raises(ValidationError):  # a block is not a bowl
        plan_schema(state).model_validate({"steps": [{"skill": "put_in", "block": "red block", "bowl": "green block"}]})


def test_schema_without_bowls_has_no_put_in():
    state = WorldState(positions=layout(Scene(objects=["red block", "green block", "blue block"]), 0))
    assert "PutInStep" not in plan_schema(state).model_json_schema()["$defs"]


def test_plan_executor_uses_the_model_for_free_text(state):
    answer = {"steps": [
        {"skill": "put_in", "block": "red block", "bowl": "red bowl"},
        {"skill": "put_on", "block": "green block", "target": "red block"},
        {"skill": "put_next_to", "block": "blue block", "target": "blue bowl", "side": "left"},
    ]}
    model = ScriptedModel([answer])
    result = PlanExecutor(model).to_plan("warm colours go in the red bowl, then tidy up", state)
    assert result.ok and result.source == "plan"
    assert result.plan == [
        PutIn(block="red block", bowl="red bowl"),
        PutOn(block="green block", target="red block"),
        PutNextTo(block="blue block", target="blue bowl", side="left"),
    ]
    prompt = model.last_prompt
    assert "Use only these objects: red block, green block, blue block, blue bowl, red bowl" in prompt
    assert "warm colours go in the red bowl" in prompt
    # The schema the model was constrained by names only this scene's objects.
    assert "purple" not in json.dumps(model.calls[0].json_schema)


def test_plan_executor_parses_first_only_when_asked(state):
    model = ScriptedModel([])
    result = PlanExecutor(model, parser_first=True).to_plan("put the red block at the middle", state)
    assert result.plan == [PutAt(block="red block", position="middle")] and model.calls == []
    # By default every y goes to the model, canonical or not, and the call is kept.
    model = ScriptedModel([{"steps": [{"skill": "put_at", "block": "red block", "position": "middle"}]}])
    executor = PlanExecutor(model)
    result = executor.to_plan("put the red block at the middle", state)
    assert result.ok and result.source == "plan" and len(model.calls) == 1
    (call,) = executor.drain_transcript()
    assert call["instruction"] == "put the red block at the middle" and call["plan"] and call["failure"] is None
    assert executor.drain_transcript() == []


def test_an_empty_instruction_fails_without_a_model_call(state):
    model = ScriptedModel([])
    result = PlanExecutor(model).to_plan("  \n ", state)
    assert result.failure is not None and result.failure.stage == "parse" and model.calls == []


def test_invalid_model_answer_is_a_plan_failure(state):
    model = ScriptedModel([{"steps": [{"skill": "put_in", "block": "purple block", "bowl": "red bowl"}]}])
    result = PlanExecutor(model).to_plan("something the parser cannot read", state)
    assert result.failure is not None and result.failure.stage == "plan" and result.plan == []
    assert "simpler goal" in result.failure.feedback_text()


def test_empty_plan_is_a_failure(state):
    result = PlanExecutor(ScriptedModel([{"steps": []}])).to_plan("be creative", state)
    assert result.failure is not None and result.failure.stage == "plan"


def test_make_executor_names(monkeypatch):
    monkeypatch.setenv("ACTIVEINTENT_UNSAFE_NO_ISOLATION", "1")  # `cap` with a model checks isolation
    assert make_executor("parse").name == "parse"
    assert make_executor("PLAN", ScriptedModel([])).name == "plan"
    assert make_executor("cap", ScriptedModel([])).name == "cap"
    with pytest.raises(ValueError, match="valid executors: parse, plan, cap"):
        make_executor("magic")

    # Without a model (methods that plan by themselves), only the canonical phrasing is read.
    state = WorldState(positions=layout(Scene(objects=["red block", "green block", "blue bowl"]), 0))
    no_model = make_executor("cap")
    assert no_model.to_plan("put the red block in the blue bowl", state).ok
    failed = no_model.to_plan("tidy the table", state)
    assert failed.failure is not None and failed.failure.stage == "parse"


def test_feedback_text():
    failure = ExecutionFailure(stage="program", message="NameError: name 'foo' is not defined (line 2)")
    text = failure.feedback_text()
    assert text.startswith("I failed to generate the goal; please generate a simpler goal similar to the previous one.")
    assert "program" in text and "foo" in text


def test_act_bench_json():
    require_namespaces()
    app = typer.Typer()

    @app.callback()
    def main() -> None:
        """Test app."""

    register(app)
    out = CliRunner().invoke(app, ["act-bench", "--json", "--programs", "4"])
    assert out.exit_code == 0, out.output
    report = json.loads(out.output)
    for key in ("parse", "plan_validation", "cap_sandboxed", "cap_sandbox_overhead"):
        assert report[key]["n"] == 4 and report[key]["mean_s"] > 0
    assert report["program_errors"] == [] and report["sandbox_startup_s"] > 0
