"""The deterministic parser reads back describe_skill's canonical phrasing and its variants."""

from __future__ import annotations

import numpy as np
import pytest

from activeintent.act.base import make_executor
from activeintent.act.parse import ParseError, parse_instruction
from activeintent.world import (
    ALL_OBJECTS,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    describe_plan,
    describe_skill,
)
from activeintent.world.skills import TABLE_POSITIONS

BLOCKS = [o for o in ALL_OBJECTS if o.endswith("block")]
BOWLS = [o for o in ALL_OBJECTS if o.endswith("bowl")]
SIDES = ["left", "right", "front", "behind", "nearest"]


def random_skill(rng: np.random.Generator):
    kind = rng.integers(5)
    block = str(rng.choice(BLOCKS))
    if kind == 0:
        return PutIn(block=block, bowl=str(rng.choice(BOWLS)))
    if kind == 1:
        return PutOn(block=block, target=str(rng.choice([b for b in BLOCKS if b != block])))
    if kind == 2:
        target = str(rng.choice([o for o in ALL_OBJECTS if o != block]))
        return PutNextTo(block=block, target=target, side=str(rng.choice(SIDES)))
    if kind == 3:
        return PutAt(block=block, position=str(rng.choice(list(TABLE_POSITIONS))))
    x, y = rng.uniform(-0.3, 0.3), rng.uniform(-0.8, -0.2)
    return PutAt(block=block, position=(round(float(x), 2), round(float(y), 2)))


def same(a, b) -> bool:
    if isinstance(a, PutAt) and isinstance(b, PutAt) and not isinstance(a.position, str):
        return a.block == b.block and np.allclose(a.position, b.position, atol=1e-9)
    return a == b


@pytest.mark.parametrize("seed", range(300))
def test_describe_skill_round_trips(seed):
    step = random_skill(np.random.default_rng(seed))
    parsed = parse_instruction(describe_skill(step), ALL_OBJECTS)
    assert len(parsed) == 1 and same(parsed[0], step), (describe_skill(step), parsed)


def _variants(text: str, rng: np.random.Generator) -> str:
    """Sloppy but canonical-enough rewritings of a described plan."""
    clauses = text.split(", then ")
    verb = str(rng.choice(["put", "place", "move", "Put", "PLACE"]))
    clauses = [c.replace("put ", f"{verb} ", 1) for c in clauses]
    if rng.random() < 0.5:
        clauses = [c.replace(" the ", " ") for c in clauses]
    if rng.random() < 0.3:  # elided verbs after the first clause
        clauses = [clauses[0]] + [c.split(" ", 1)[1] for c in clauses[1:]]
    joiner = str(rng.choice([", then ", ", ", "; ", " and ", ". ", ", and then ", " then "]))
    out = joiner.join(clauses)
    if rng.random() < 0.5:
        out = out[0].upper() + out[1:] + "."
    return out.replace("gray", "grey") if rng.random() < 0.3 else out


@pytest.mark.parametrize("seed", range(200))
def test_plans_round_trip_with_variants(seed):
    rng = np.random.default_rng(1000 + seed)
    plan = [random_skill(rng) for _ in range(int(rng.integers(1, 5)))]
    text = _variants(describe_plan(plan), rng)
    parsed = parse_instruction(text, ALL_OBJECTS)
    assert len(parsed) == len(plan) and all(same(a, b) for a, b in zip(parsed, plan, strict=True)), text


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("stack the green block on the red block", [PutOn(block="green block", target="red block")]),
        ("stack the green block on top of the red block", [PutOn(block="green block", target="red block")]),
        ("put red block into blue bowl", [PutIn(block="red block", bowl="blue bowl")]),
        ("put the red block onto the blue bowl", [PutIn(block="red block", bowl="blue bowl")]),
        ("move the red cube to the blue bowl", [PutIn(block="red block", bowl="blue bowl")]),
        ("put the red block to the left of the blue bowl", [PutNextTo(block="red block", target="blue bowl", side="left")]),
        ("put the red block beside the blue bowl", [PutNextTo(block="red block", target="blue bowl")]),
        ("put the red block in the middle", [PutAt(block="red block", position="middle")]),
        ("Put the red block at the Top Left Corner.", [PutAt(block="red block", position="top left corner")]),
        ("put the red block at (0.1, -0.5)", [PutAt(block="red block", position=(0.1, -0.5))]),
        (
            "put the red block in the blue bowl, the green block on the red block",
            [PutIn(block="red block", bowl="blue bowl"), PutOn(block="green block", target="red block")],
        ),
        (
            "First put the grey block in the blue bowl. Then put the red block next to the grey block",
            [PutIn(block="gray block", bowl="blue bowl"), PutNextTo(block="red block", target="gray block")],
        ),
        ("do nothing", []),
    ],
)
def test_tolerated_phrasings(text, expected):
    objects = ["red block", "green block", "gray block", "blue bowl"]
    assert parse_instruction(text, objects) == expected


def test_unknown_object_lists_the_scene():
    objects = ["red block", "green block", "blue bowl"]
    with pytest.raises(ParseError) as err:
        parse_instruction("put the red block in the purple bowl", objects)
    assert err.value.kind == "unknown_object"
    assert "purple bowl" in str(err.value) and "red block, green block, blue bowl" in str(err.value)
    failure = err.value.failure()
    assert failure.stage == "parse" and failure.details["unknown"] == ["purple bowl"]


@pytest.mark.parametrize(
    "text",
    ["put all the blocks in the bowl", "stack everything", "", "put the red block somewhere nice",
     "make the table tidy, then rest"],
)
def test_non_canonical_is_a_syntax_error(text):
    with pytest.raises(ParseError) as err:
        parse_instruction(text, ["red block", "green block", "blue bowl"])
    assert err.value.kind == "syntax"


def test_parse_executor_reports_failures_as_data(state):
    ex = make_executor("parse")
    ok = ex.to_plan("put the red block in the blue bowl, then put the green block on the red block", state)
    assert ok.ok and ok.source == "parse" and len(ok.plan) == 2
    bad = ex.to_plan("put every block where it belongs", state)
    assert bad.failure is not None and bad.failure.stage == "parse" and bad.plan == []
    text = bad.failure.feedback_text()
    assert "I failed to generate the goal; please generate a simpler goal similar to the previous one" in text
    assert "cannot read" in text


def test_infeasible_step_is_a_skill_failure_with_the_plan_kept(state):
    # The red block ends up under the green block, so it cannot then go into a bowl.
    result = make_executor("parse").to_plan(
        "put the green block on the red block, then put the red block in the blue bowl", state
    )
    assert len(result.plan) == 2
    assert result.failure is not None and result.failure.stage == "skill"
    assert result.failure.details["failed_steps"][0]["index"] == 1
    assert "under the green block" in result.failure.message
