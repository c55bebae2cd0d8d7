"""The deterministic parser reads back describe_skill's canonical phrasing and its variants."""

from __future__ import annotations

import numpy as np
import pytest

from activeintent.act.executors import make_executor
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


def test_describe_then_parse_gives_back_the_plan():
    """Property: parsing the description of a random plan (also sloppily rewritten) yields the
    plan. One seeded loop; known answers for each direction are in the tests below, since a
    mistake made the same way in describe_skill and in the parser keeps this property true."""
    rng = np.random.default_rng(20240518)
    failures = []
    for _ in range(400):  # single skills, canonical text
        step = random_skill(rng)
        text = describe_skill(step)
        parsed = parse_instruction(text, ALL_OBJECTS)
        if not (len(parsed) == 1 and same(parsed[0], step)):
            failures.append((text, parsed))
    for _ in range(300):  # plans of 1-4 skills, rewritten with other verbs, joiners, case
        plan = [random_skill(rng) for _ in range(int(rng.integers(1, 5)))]
        text = _variants(describe_plan(plan), rng)
        try:
            parsed = parse_instruction(text, ALL_OBJECTS)
        except ParseError as exc:
            failures.append((text, exc))
            continue
        if not (len(parsed) == len(plan) and all(same(a, b) for a, b in zip(parsed, plan, strict=True))):
            failures.append((text, parsed))
    assert not failures, f"{len(failures)} round trips failed, e.g. {failures[:3]}"


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


# ---- known answers: what describe_skill writes ------------------------------------------------

@pytest.mark.parametrize(
    ("step", "text"),
    [
        (PutIn(block="red block", bowl="blue bowl"), "put the red block in the blue bowl"),
        (PutOn(block="red block", target="green block"), "put the red block on the green block"),
        (PutNextTo(block="red block", target="blue bowl", side="left"), "put the red block left of the blue bowl"),
        (PutNextTo(block="red block", target="blue bowl", side="right"), "put the red block right of the blue bowl"),
        (PutNextTo(block="red block", target="green block", side="front"),
         "put the red block in front of the green block"),
        (PutNextTo(block="red block", target="green block", side="behind"),
         "put the red block behind the green block"),
        (PutNextTo(block="red block", target="green block"), "put the red block next to the green block"),
        (PutAt(block="red block", position="top left corner"), "put the red block at the top left corner"),
        (PutAt(block="red block", position="middle"), "put the red block at the middle"),
        (PutAt(block="red block", position=(0.1, -0.5)), "put the red block at (0.10, -0.50)"),
        (PutAt(block="red block", position=(-0.2, -0.35)), "put the red block at (-0.20, -0.35)"),
    ],
)
def test_describe_skill_known_answers(step, text):
    assert describe_skill(step) == text


def test_describe_plan_known_answers():
    plan = [PutIn(block="red block", bowl="blue bowl"), PutOn(block="green block", target="red block")]
    assert describe_plan(plan) == "put the red block in the blue bowl, then put the green block on the red block"
    assert describe_plan([]) == "do nothing"


# ---- known answers: what users type -----------------------------------------------------------

SCENE = ["red block", "green block", "blue block", "blue bowl", "red bowl"]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("put the red block in the blue bowl", [PutIn(block="red block", bowl="blue bowl")]),
        ("put the red block on the green block", [PutOn(block="red block", target="green block")]),
        ("put the red block on the blue bowl", [PutIn(block="red block", bowl="blue bowl")]),
        ("put the red block to the left of the blue bowl",
         [PutNextTo(block="red block", target="blue bowl", side="left")]),
        ("put the red block to the right of the green block",
         [PutNextTo(block="red block", target="green block", side="right")]),
        ("put the red block left of the blue bowl", [PutNextTo(block="red block", target="blue bowl", side="left")]),
        ("put the red block in front of the blue bowl",
         [PutNextTo(block="red block", target="blue bowl", side="front")]),
        ("put the red block behind the green block",
         [PutNextTo(block="red block", target="green block", side="behind")]),
        ("put the red block next to the green block", [PutNextTo(block="red block", target="green block")]),
        ("put the red block at the top left corner", [PutAt(block="red block", position="top left corner")]),
        ("put the red block at the bottom right corner",
         [PutAt(block="red block", position="bottom right corner")]),
        ("put the blue block at the left side", [PutAt(block="blue block", position="left side")]),
        ("put the red block at (0.1, -0.5)", [PutAt(block="red block", position=(0.1, -0.5))]),
        (
            "put the red block in the blue bowl then put the green block on the red block",
            [PutIn(block="red block", bowl="blue bowl"), PutOn(block="green block", target="red block")],
        ),
        (
            "put the red block in the red bowl, then put the blue block in the blue bowl, "
            "then put the green block to the left of the red bowl",
            [PutIn(block="red block", bowl="red bowl"), PutIn(block="blue block", bowl="blue bowl"),
             PutNextTo(block="green block", target="red bowl", side="left")],
        ),
    ],
)
def test_parse_known_answers(text, expected):
    assert parse_instruction(text, SCENE) == expected


@pytest.mark.parametrize(
    ("phrase", "xy"),
    [
        ("at the top left corner", (-0.25, -0.25)),
        ("at the top side", (0.0, -0.25)),
        ("at the left side", (-0.25, -0.5)),
        ("in the middle", (0.0, -0.5)),
        ("at the bottom right corner", (0.25, -0.75)),
    ],
)
def test_named_positions_are_the_table_layout(phrase, xy):
    """The parsed position names the place of the Code-as-Policies table layout the user means."""
    (step,) = parse_instruction(f"put the red block {phrase}", SCENE)
    assert TABLE_POSITIONS[step.position] == xy


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
