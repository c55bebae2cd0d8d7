"""The goal language's versions, and the node types language 2 added (goals/requested.py)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from activeintent.goals import planner
from activeintent.goals.facts import facts
from activeintent.goals.language import (
    LATEST,
    NODES,
    Each,
    Form,
    all_clauses,
    nodes,
    parse_goal,
    speaking,
)
from activeintent.goals.requested import LIGHTNESS
from activeintent.learners.lang.hypotheses import LangSpace
from activeintent.learners.lang.learner import LangConfig, LangLearner
from activeintent.world import PutAt, PutIn, PutNextTo, PutOn, WorldState, apply_skill, layout
from activeintent.world.scene import Scene


def _speaks(clause, version: int) -> bool:
    kinds = [("selector", clause.sel)]
    kinds.append(("structure", clause.struct) if isinstance(clause, Form) else ("relation", clause.rel))
    return all(key in nodes(kind, version) for kind, key in kinds)


def test_node_types_register_in_their_order():
    """Registration order is enumeration order (the hypothesis space, committed results): language
    1's node types in the order of its modules (goals/__init__.py), then language 2's."""
    assert {kind: list(reg) for kind, reg in NODES.items()} == {
        "selector": ["all", "colour", "class", "matching", "all-but", "colours", "all-but-colours"],
        "relation": ["in-bowl", "in-the-bowl", "on-block", "on-the-block", "on-table", "next-to", "side", "region",
                     "in-bowl-at", "side-of-bowls", "table-part", "in-the-bowl-if-there", "on-the-block-if-there",
                     "next-to-if-there", "side-if-there", "in-bowl-else", "next-to-bowl-at"],
        "structure": ["row", "column", "tower", "towers-by-class", "two-towers", "one-bowl", "separate-bowls",
                      "cluster", "corners", "each-bowl", "around-bowl", "groups-by-class", "stacks", "tower-by-shade",
                      "row-by-shade", "tower-by-name", "row-by-name", "by-each-bowl", "two-bowls", "bowl-load",
                      "even-halves"],
    }


def test_language_1_is_the_language_earlier_episodes_ran_in():
    with speaking(1):
        clauses = all_clauses()
        own_bowl = parse_goal("every all: in-bowl:same").bits
    assert len(clauses) == 25_775  # as before the language grew (data/requests/TRANSLATION_LANGUAGE.md)
    assert own_bowl == pytest.approx(12.714245517666122)  # its sentence there: 12.7 bits
    assert all(_speaks(c, 1) for c in clauses)
    assert LATEST == 2 and len(all_clauses()) > len(clauses)
    assert parse_goal("every all: in-bowl:same").bits > own_bowl  # more choices at every point


@pytest.mark.parametrize("version", [1, 2])
def test_each_language_s_length_prior_sums_to_one_over_its_clauses(version):
    with speaking(version):
        total = math.fsum(2.0 ** -c.bits for c in all_clauses())
    assert total == pytest.approx(1.0, abs=1e-9)


def test_a_record_written_before_the_language_grew_replays_in_language_1():
    from activeintent.bench.legacy import migrated
    from activeintent.bench.work import read_bench_config
    from activeintent.runner import check_spec
    from activeintent.spec import RunSpec

    old = {"config": {"options": {"method": "lang-stop", "prior": "length"}}}
    assert migrated(old)["config"]["spec"]["learner"]["settings"]["language"] == 1
    folder = read_bench_config(Path(__file__).resolve().parents[2] / "docs" / "results" / "heldout-freeze" / "bench.json")
    assert folder.run.learner.settings["language"] == 1  # its bench.json predates the field
    assert check_spec(RunSpec.from_options(method="lang-stop", llm="none")).learner.settings["language"] == LATEST
    with pytest.raises(ValueError, match="unknown language version 7"):
        check_spec(RunSpec.from_options(method="lang-stop", llm="none", language=7))


def test_a_language_1_learner_never_admits_a_goal_of_language_2():
    with speaking(1):
        start = [parse_goal(k) for k in ("every all: in-bowl:same", "form tower:any all:", "every colour:red on-table:")]
    space = LangSpace(start, language=1)
    learner = LangLearner("stop", rng=0, config=LangConfig(language=1, rejuvenate_top=3, join_partners=3),
                          hypotheses=space.hypotheses)
    learner._rejuvenate()
    added = learner.added.goals
    assert added and all(_speaks(c, 1) for g in added for c in g.clauses)
    grown = LangLearner("stop", rng=0, config=LangConfig(language=2, rejuvenate_top=3, join_partners=3),
                        hypotheses=LangSpace(start, language=2).hypotheses)
    grown._rejuvenate()
    assert any(not _speaks(c, 1) for g in grown.added.goals for c in g.clauses)


# ---- the node types of language 2 ----------------------------------------------------------------


def _state(objects: list[str], *steps) -> WorldState:
    state = WorldState(positions=layout(Scene(objects=objects), 3))
    for step in steps:
        state, fail = apply_skill(state, step)
        assert fail is None, (step, fail)
    return state


def _holds(key: str, state: WorldState) -> bool:
    return parse_goal(key).holds(facts(state))


def test_a_bowl_picked_by_its_place_is_the_one_standing_there():
    s = _state(["red block", "blue block", "blue bowl", "red bowl"])
    f = facts(s)
    left = min(f.bowls, key=lambda w: f.xy[w][0])
    s = _state(["red block", "blue block", "blue bowl", "red bowl"], PutIn(block="red block", bowl=left),
               PutIn(block="blue block", bowl=left))
    assert _holds("every all: in-bowl-at:leftmost", s)
    assert not _holds("every all: in-bowl-at:rightmost", s)


def test_a_clause_if_there_holds_on_a_day_its_object_is_absent():
    without = _state(["green block", "red block", "blue bowl"])
    assert _holds("every colour:green in-the-bowl-if-there:green", without)
    assert parse_goal("every colour:green in-the-bowl-if-there:green").possible(("green block", "red block", "blue bowl"))
    assert not parse_goal("every colour:green in-the-bowl:green").possible(("green block", "red block", "blue bowl"))
    with_bowl = _state(["green block", "red block", "green bowl"])
    assert not _holds("every colour:green in-the-bowl-if-there:green", with_bowl)
    assert _holds("every colour:green in-the-bowl-if-there:green",
                  _state(["green block", "red block", "green bowl"], PutIn(block="green block", bowl="green bowl")))


def test_stacks_in_pairs_and_no_higher_than_two():
    objs = ["red block", "blue block", "green block", "yellow block", "blue bowl"]
    pairs = _state(objs, PutOn(block="red block", target="blue block"), PutOn(block="green block", target="yellow block"))
    assert _holds("form stacks:pairs all:", pairs) and _holds("form stacks:max-2 all:", pairs)
    three = _state(objs, PutOn(block="red block", target="blue block"), PutOn(block="green block", target="red block"))
    assert not _holds("form stacks:pairs all:", three) and not _holds("form stacks:max-2 all:", three)
    assert _holds("form stacks:max-3 all:", three)


def test_the_shade_order_is_the_palette_s_lightness():
    assert min(LIGHTNESS, key=LIGHTNESS.get) == "purple" and max(LIGHTNESS, key=LIGHTNESS.get) == "yellow"
    objs = ["yellow block", "purple block", "red block"]
    dark_up = _state(objs, PutOn(block="red block", target="purple block"), PutOn(block="yellow block", target="red block"))
    assert _holds("form tower-by-shade:dark-first all:", dark_up)
    assert not _holds("form tower-by-shade:light-first all:", dark_up)
    assert _holds("form tower-by-name:alphabetical all:", _state(
        objs, PutOn(block="red block", target="purple block"), PutOn(block="yellow block", target="red block")))


def test_two_bowls_one_by_each_bowl_the_rest_in_bowls_or_else_a_place():
    objs = ["red block", "orange block", "blue block", "red bowl", "blue bowl"]
    split = _state(objs, PutIn(block="red block", bowl="red bowl"), PutIn(block="orange block", bowl="red bowl"),
                   PutIn(block="blue block", bowl="blue bowl"))
    assert _holds("form two-bowls: class:warm", split)
    assert not _holds("form two-bowls: class:warm", _state(objs, PutIn(block="red block", bowl="red bowl")))
    tags = _state(objs, PutNextTo(block="red block", target="red bowl", side="front"),
                  PutNextTo(block="blue block", target="blue bowl", side="front"), PutIn(block="orange block", bowl="red bowl"))
    assert _holds("form by-each-bowl:front all:", tags)
    assert _holds("every all: in-bowl-else:next-to-a-bowl", tags)
    assert not _holds("form by-each-bowl:behind all:", tags)
    assert not _holds("every all: in-bowl-else:back left corner", tags)


def test_bowl_loads_and_even_halves():
    objs = ["red block", "orange block", "blue block", "green block", "red bowl", "blue bowl"]
    three = _state(objs, *[PutIn(block=b, bowl="red bowl") for b in objs[:3]])
    assert _holds("form bowl-load:max-3 all:", three) and not _holds("form bowl-load:max-2 all:", three)
    even = _state(objs, PutIn(block="red block", bowl="red bowl"), PutIn(block="orange block", bowl="red bowl"),
                  PutIn(block="blue block", bowl="blue bowl"), PutIn(block="green block", bowl="blue bowl"))
    assert _holds("form bowl-load:even all:", even) and not _holds("form bowl-load:even all:", three)
    halves = _state(objs)
    for block, x in (("red block", -0.2), ("orange block", -0.2), ("blue block", 0.2), ("green block", 0.2)):
        halves = _put_in_half(halves, block, x)
    assert _holds("form even-halves: all:", halves)
    lopsided = _put_in_half(halves, "blue block", -0.2)
    assert not _holds("form even-halves: all:", lopsided)


def _put_in_half(state: WorldState, block: str, x: float) -> WorldState:
    """``block`` set on a free table point with the sign of ``x`` (left < 0 < right)."""
    for y in (-0.3, -0.4, -0.5, -0.6, -0.7):
        for dx in (0.0, 0.06, -0.06):
            new, fail = apply_skill(state, PutAt(block=block, position=(x + dx, y)))
            if fail is None:
                return new
    raise AssertionError(f"no free point for {block} at x = {x}")


def test_the_planner_reaches_goals_of_every_new_node_type():
    rng = np.random.default_rng(11)
    new = [c for c in all_clauses() if not _speaks(c, 1)]
    by_type: dict[str, list] = {}
    for c in new:
        by_type.setdefault(c.sel if not _speaks(Each("every", c.sel, c.sp, "on-table", ""), 1)
                           else (c.struct if isinstance(c, Form) else c.rel), []).append(c)
    from activeintent.learners.bayes.hypotheses import random_scene

    for name, clauses in sorted(by_type.items()):
        reached = 0
        for _ in range(40):
            c = clauses[int(rng.integers(len(clauses)))]
            goal = parse_goal(c.key)
            scene = random_scene(rng)
            if not goal.possible(tuple(scene.objects)):
                continue
            state = WorldState(positions=layout(scene, int(rng.integers(1 << 30))))
            steps = planner.plan(goal, state)
            if steps is None:
                continue
            for step in steps:
                state, _ = apply_skill(state, step)
            assert goal.holds(facts(state)), (c.key, steps)
            reached += 1
        assert reached >= 5, name
