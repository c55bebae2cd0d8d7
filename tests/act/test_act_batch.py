"""Model-proposed predicates judge many worlds in the sandbox: large batches become several
programs within the guard's size limit, and no answer is silently lost."""

from __future__ import annotations

import pytest

from activeintent.act.guard import MAX_PROGRAM_CHARS, check_program
from activeintent.learners.bayes.proposals import SandboxRunner, batch_programs

BODY = "return world['in_bowl'].get('red block') == 'green bowl'"
NAMES = ["red block", "blue block", "yellow block", "red bowl", "green bowl", "blue bowl"]


def _world(i: int) -> dict:
    bowl = "green bowl" if i % 3 == 0 else "red bowl"
    return {
        "blocks": NAMES[:3], "bowls": NAMES[3:], "color": {n: n.split()[0] for n in NAMES}, "warm": ["red", "yellow"],
        "in_bowl": {"red block": bowl}, "on": {}, "next_to": [["blue block", "yellow block"]],
        "position": {n: [round(0.01 * i + 0.05 * k, 4), round(-0.5 + 0.01 * k, 4)] for k, n in enumerate(NAMES)},
        "table_position": {n: "middle" for n in NAMES},
    }


def test_many_worlds_make_several_programs_within_the_limit():
    worlds = [_world(i) for i in range(120)]
    batches = batch_programs(BODY, worlds)
    assert len(batches) > 1
    assert [w for _, group in batches for w in group] == worlds
    for program, _ in batches:
        assert len(program) <= MAX_PROGRAM_CHARS
        check_program(program)


def test_one_oversized_world_is_an_error_not_a_silent_drop():
    huge = _world(0) | {"table_position": {f"object {i}": "middle" for i in range(3000)}}
    with pytest.raises(ValueError, match="over"):
        batch_programs(BODY, [huge])


def test_runner_answers_every_world(sandbox):
    worlds = [_world(i) for i in range(60)]
    answers = SandboxRunner(sandbox)(BODY, worlds)
    assert answers == [i % 3 == 0 for i in range(60)]
