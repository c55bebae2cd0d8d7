"""Code as Policies: benign and CaP-style programs run in the sandbox and become plans."""

from __future__ import annotations

import os
import select
import signal

import numpy as np
import pytest
from act_helpers import require_namespaces

from activeintent.act.cap import CapExecutor, extract_program
from activeintent.act.robot_api import RobotAPI
from activeintent.act.sandbox import Sandbox, SandboxLimits
from activeintent.llm.scripted import ScriptedModel
from activeintent.world import PutAt, PutIn, PutOn, apply_plan

BENIGN: list[tuple[str, str, int]] = [  # (id, program, number of robot calls)
    ("loop", "for b in ['red block', 'green block']:\n    put_first_on_second(b, 'red bowl')", 2),
    ("comprehension", "blocks = [n for n in get_obj_names() if n.endswith('block')]\n"
                      "pairs = {b: b.replace('block', 'bowl') for b in blocks}\n"
                      "for b, w in pairs.items():\n    if is_obj_visible(w):\n        put_first_on_second(b, w)", 2),
    ("numpy-math", "p = np.mean([get_obj_pos(n) for n in ['red bowl', 'blue bowl']], axis=0)\n"
                   "d = float(np.linalg.norm(p - get_obj_pos('green block')))\n"
                   "say(round(d, 3))\nput_first_on_second('green block', p)", 1),
    ("fstring", "n = len(get_obj_names())\nsay(f'I see {n} objects, {n / 2:.1f} pairs')\n"
                "put_first_on_second('blue block', 'top right corner')", 1),
    ("helper-function", "def blocks():\n    return sorted(o for o in get_obj_names() if 'block' in o)\n"
                        "def first_two(xs):\n    return xs[:2]\nstack_objects_in_order(object_names=first_two(blocks()))", 1),
    ("lambda-min", "target = min(['red block', 'green block'], key=lambda b: "
                   "np.linalg.norm(get_obj_pos(b) - get_obj_pos('blue bowl')))\n"
                   "put_first_on_second(target, 'blue bowl')", 1),
    ("try-except", "try:\n    put_first_on_second('purple block', 'blue bowl')\nexcept ValueError as e:\n"
                   "    say('no purple block')\n    put_first_on_second('red block', 'blue bowl')", 1),
    ("while-print", "i = 0\nwhile i < 3:\n    print('step', i)\n    i += 1\nput_first_on_second('red block', 'middle')", 1),
    ("math-and-tuple", "x, y = get_obj_pos('red bowl')\nangle = math.atan2(y, x)\n"
                       "put_first_on_second('red block', (x + 0.1 * math.cos(angle), y))", 1),
]


@pytest.mark.parametrize(("name", "program", "n_calls"), BENIGN, ids=[b[0] for b in BENIGN])
def test_benign_programs_run(name, program, n_calls, sandbox, state):
    result = sandbox.run(program, state)
    assert result.ok, result.error
    assert len(result.skills) == n_calls


# Programs written in the Code-as-Policies tabletop style, using only its API: run unchanged.
CAP_STYLE = [
    (
        "objects = ['red block', 'green block', 'blue block', 'blue bowl', 'red bowl']\n"
        "# put the blocks in the blue bowl.\n"
        "block_names = ['red block', 'green block', 'blue block']\n"
        "bowl_name = 'blue bowl'\n"
        "for block_name in block_names:\n"
        "    put_first_on_second(block_name, bowl_name)\n",
        [PutIn(block=b, bowl="blue bowl") for b in ("red block", "green block", "blue block")],
    ),
    (
        "# stack the blocks with the blue one on the bottom.\n"
        "say('Ok - stacking')\n"
        "stack_objects_in_order(object_names=['blue block', 'green block', 'red block'])\n",
        [PutOn(block="green block", target="blue block"), PutOn(block="red block", target="green block")],
    ),
    (
        "# move the red block to the top right corner.\n"
        "corner_pos = parse_position('top right corner')\n"
        "put_first_on_second('red block', corner_pos)\n",
        [PutAt(block="red block", position=(0.25, -0.25))],
    ),
    (
        "# put the green block in the corner closest to the red bowl.\n"
        "corner_name = get_corner_name(get_obj_pos('red bowl'))\n"
        "put_first_on_second('green block', corner_name)\n",
        None,
    ),
    (
        "# line up the blocks along the bottom side.\n"
        "block_names = ['red block', 'green block', 'blue block']\n"
        "start, end = denormalize_xy([0.2, 0.1]), denormalize_xy([0.8, 0.1])\n"
        "for pos, block_name in zip(np.linspace(start, end, len(block_names)), block_names):\n"
        "    put_first_on_second(block_name, pos)\n",
        None,
    ),
    (
        "# if there is a purple block, put it in the red bowl; otherwise put the blue block there.\n"
        "if is_obj_visible('purple block'):\n"
        "    put_first_on_second('purple block', 'red bowl')\n"
        "else:\n"
        "    put_first_on_second('blue block', 'red bowl')\n",
        [PutIn(block="blue block", bowl="red bowl")],
    ),
]


@pytest.mark.parametrize(("program", "expected"), CAP_STYLE)
def test_cap_style_programs_run_unchanged(program, expected, sandbox, state):
    result = sandbox.run(program, state)
    assert result.ok, result.error
    if expected is not None:
        assert result.skills == expected
    _, failures = apply_plan(state, result.skills)
    assert failures == [None] * len(result.skills)


def test_get_obj_pos_sees_earlier_moves(state):
    api = RobotAPI(state)
    api.put_first_on_second("red block", "top left corner")
    assert np.allclose(api.get_obj_pos("red block"), (-0.25, -0.25))
    # A point on a block or inside a bowl means "on it" / "in it", as the robot would drop it.
    api.put_first_on_second("green block", api.get_obj_pos("red block"))
    api.put_first_on_second("blue block", api.get_obj_pos("red bowl") + [0.01, 0.0])
    assert api.skills[1] == PutOn(block="green block", target="red block")
    assert api.skills[2] == PutIn(block="blue block", bowl="red bowl")
    assert api.skill_failures == [None, None, None]


def test_parse_position_forms(state):
    api = RobotAPI(state)
    assert np.allclose(api.parse_position("the top left corner of the table"), (-0.25, -0.25))
    assert np.allclose(api.parse_position("center"), (0.0, -0.5))
    left = api.parse_position("10cm left of the blue bowl")
    assert np.allclose(left, api.get_obj_pos("blue bowl") + [-0.1, 0.0])
    mid = api.parse_position("between the red block and the blue bowl")
    assert np.allclose(mid, (api.get_obj_pos("red block") + api.get_obj_pos("blue bowl")) / 2)
    assert api.get_side_name((0.0, -0.22)) == "top side"
    assert api.get_corner_name((0.3, -0.8)) == "bottom right corner"
    assert np.allclose(api.denormalize_xy([0.5, 0.5]), (0.0, -0.5))
    with pytest.raises(ValueError, match="named position"):
        api.parse_position("somewhere over the rainbow")


def test_extract_program():
    assert extract_program("Here:\n```python\nsay('a')\n```\nDone.") == "say('a')"
    assert extract_program("say('b')\n") == "say('b')"


def test_executor_runs_model_program(sandbox, state):
    model = ScriptedModel(["```python\nfor b in ['red block', 'blue block']:\n"
                           "    put_first_on_second(b, b.replace('block', 'bowl'))\n```"])
    result = CapExecutor(model, sandbox=sandbox).to_plan("put the blocks in the bowls of their colour", state)
    assert result.ok and result.source == "cap"
    assert result.plan == [PutIn(block="red block", bowl="red bowl"), PutIn(block="blue block", bowl="blue bowl")]
    assert "objects = ['red block'" in model.last_prompt
    assert "# put the blocks in the bowls of their colour." in model.last_prompt


def test_canonical_instruction_skips_the_model_only_parser_first(sandbox, state):
    model = ScriptedModel([])
    result = CapExecutor(model, sandbox=sandbox, parser_first=True).to_plan("put the red block in the red bowl", state)
    assert result.ok and result.source == "parse" and model.calls == []
    # Code as Policies proper: a program is written for every y, even a canonical one.
    model = ScriptedModel(["put_first_on_second('red block', 'red bowl')"])
    executor = CapExecutor(model, sandbox=sandbox)
    result = executor.to_plan("put the red block in the red bowl", state)
    assert result.ok and result.source == "cap" and len(model.calls) == 1
    (call,) = executor.drain_transcript()
    assert call["program"] == "put_first_on_second('red block', 'red bowl')"
    assert call["plan"] == "put the red block in the red bowl"


def test_multi_line_instruction_becomes_one_comment(sandbox, state):
    model = ScriptedModel(["put_first_on_second('red block', 'red bowl')"])
    CapExecutor(model, sandbox=sandbox).to_plan("sort the blocks:\nred goes to red.", state)
    assert "# sort the blocks: red goes to red.\n" in model.last_prompt + "\n"


def test_program_without_robot_calls_fails(sandbox, state):
    result = CapExecutor(ScriptedModel(["say('hello')"]), sandbox=sandbox).to_plan("greet", state)
    assert result.failure is not None and result.failure.stage == "program"
    assert "no robot calls" in result.failure.message and result.said == ["hello"]


def test_wall_time_limit_kills(state):
    require_namespaces()
    with Sandbox(SandboxLimits(cpu_seconds=30, wall_seconds=1.0), isolation="bwrap") as sb:
        result = sb.run("while True:\n    pass", state)
        assert result.error_kind == "wall" and "wall-time" in result.error
        assert sb.run("put_first_on_second('red block', 'blue bowl')", state).ok


def test_dead_worker_is_replaced(state):
    require_namespaces()
    with Sandbox(isolation="bwrap") as sb:
        os.killpg(sb.worker_pid, signal.SIGKILL)
        # bwrap runs the worker in a session of its own that dies *after* bwrap (die-with-parent):
        # wait until nothing holds the pipe, else the dying runner may still take the program.
        sb._proc.wait(timeout=10)
        fd = sb._proc.stdout.fileno()
        assert select.select([fd], [], [], 10)[0] and os.read(fd, 1) == b""
        result = sb.run("put_first_on_second('red block', 'blue bowl')", state)
        assert result.ok and len(result.skills) == 1


def test_objects_variable_as_in_cap_prompts(sandbox, state):
    program = (
        "for name in objects:\n    if 'block' in name and is_obj_visible(name):\n"
        "        put_first_on_second(name, 'blue bowl')"
    )
    result = sandbox.run(program, state)
    assert result.ok and [s.block for s in result.skills] == state.blocks
