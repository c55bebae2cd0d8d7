"""The heldout2 suite (suites/heldout2.py): registered as its own suite; for every
intention, on 20 scenes of its own sampler, the oracle plan run through the world model satisfies
it (score 1.0) without a step that moves away, and the initial layout seldom does; hand-built
boundary states that nearly satisfy an intention do not."""

import numpy as np
import pytest

from activeintent.suites import SUITE_NAMES, resolve, suite, suite_of
from activeintent.suites.heldout2 import HELDOUT2, heldout2_intentions
from activeintent.world import (
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    WorldState,
    apply_skill,
    layout,
)
from helpers import BOWLS, IN, UP, S, T

NAMES = [it.name for it in heldout2_intentions()]
SEEDS = range(20)
FRONT = 0.097  # PutNextTo's centre offset from a bowl: bowl rim 6.5 + gap 1.2 + half a block 2 cm


def initial(intention, seed):
    scene = intention.sample_scene(np.random.default_rng(seed))
    return scene, WorldState(positions=layout(scene, seed))


def execute(state, plan):
    """Run the plan through the world model; every step must succeed. Returns the states."""
    states = [state]
    for step in plan:
        after, failure = apply_skill(states[-1], step)
        assert failure is None, (step, failure.reason)
        states.append(after)
    return states


# --- the suite --------------------------------------------------------------------------------


def test_suite_has_at_least_20_uniquely_named_prefixed_described_intentions():
    assert len(NAMES) >= 20
    assert len(set(NAMES)) == len(NAMES)
    assert all(n.startswith("h2-") for n in NAMES)
    assert len({cls for cls in HELDOUT2}) == len(HELDOUT2)
    for it in heldout2_intentions():
        d = it.description
        assert d and d[0].isupper() and d.endswith(".") and d.count(". ") == 0, d


def test_suite_is_registered_everywhere_a_suite_or_a_name_is_accepted():
    assert "heldout2" in SUITE_NAMES
    assert suite("heldout2") == NAMES
    for name in NAMES:
        assert suite_of(name) == "heldout2"
        assert resolve(name).name == name
    # no name is shared with another suite (names only, never printed)
    others = {n for s in SUITE_NAMES if s != "heldout2" for n in suite(s)}
    assert not bool(set(NAMES) & others)


def test_sampled_scenes_are_deterministic_and_have_3_to_5_objects():
    for it in heldout2_intentions():
        for seed in range(5):
            a = it.sample_scene(np.random.default_rng(seed))
            assert a == it.sample_scene(np.random.default_rng(seed))
            assert 3 <= len(a.objects) <= 5, (it.name, a)


# --- oracle plans on sampled scenes -----------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_oracle_plan_satisfies_the_intention_on_20_sampled_scenes(name):
    it = resolve(name)
    for seed in SEEDS:
        scene, state = initial(it, seed)
        assert it.feasible(scene), (name, scene)
        plan = it.plan(state)
        assert plan is not None, (name, seed, scene)
        states = execute(state, plan)
        assert it.satisfied(states[-1]), (name, seed, scene, plan)
        assert it.score(states[-1]) == 1.0
        # the oracle's own steps never move away from the intention
        for step, before, after in zip(plan, states[:-1], states[1:], strict=True):
            assert not it.step_moves_away(before, after, step), (name, seed, step)


@pytest.mark.parametrize("name", NAMES)
def test_the_initial_layout_seldom_satisfies_the_intention(name):
    it = resolve(name)
    satisfied = 0
    for seed in SEEDS:
        _, state = initial(it, seed)
        ok = it.satisfied(state)
        satisfied += ok
        assert 0.0 <= it.score(state) <= 1.0
        assert (it.score(state) == 1.0) == ok
    assert satisfied <= 0.2 * len(SEEDS), (name, satisfied)


# --- boundary states: nearly, but not, what was asked -----------------------------------------

RB = (-0.2, -0.3)  # red bowl (BOWLS)
BB = (0.2, -0.3)  # blue bowl
# (intention, states that satisfy it, states that nearly do but must not)
BOUNDARY = {
    "h2-row-along-back-edge": (
        [S(red_block=(-0.05, -0.25, T), green_block=(0.002, -0.25, T), cyan_block=(0.054, -0.255, T),
           **BOWLS)],
        [
            # a gap in the row
            S(red_block=(-0.05, -0.25, T), green_block=(0.002, -0.25, T), cyan_block=(0.12, -0.25, T), **BOWLS),
            # a good row, but across the middle of the table
            S(red_block=(-0.05, -0.5, T), green_block=(0.002, -0.5, T), cyan_block=(0.054, -0.5, T), **BOWLS),
            # along the back edge, but one block stacked
            S(red_block=(-0.05, -0.25, T), green_block=(0.002, -0.25, T), cyan_block=(0.002, -0.25, T + UP),
              **BOWLS),
        ],
    ),
    "h2-alternating-row": (
        [S(red_block=(-0.05, -0.5, T), green_block=(0.002, -0.5, T), orange_block=(0.054, -0.5, T))],
        [
            S(red_block=(-0.05, -0.5, T), orange_block=(0.002, -0.5, T), green_block=(0.054, -0.5, T)),
            S(red_block=(-0.05, -0.5, T), green_block=(0.002, -0.5, T), orange_block=(0.054, -0.535, T)),
        ],
    ),
    "h2-in-front-of-own-bowl": (
        [S(red_block=(RB[0], RB[1] - FRONT, T), blue_block=(BB[0] + 0.03, BB[1] - FRONT, T), **BOWLS)],
        [
            # the red block behind its bowl
            S(red_block=(RB[0], RB[1] + FRONT, T), blue_block=(BB[0], BB[1] - FRONT, T), **BOWLS),
            # in front of the wrong bowls
            S(red_block=(BB[0], BB[1] - FRONT, T), blue_block=(RB[0], RB[1] - FRONT, T), **BOWLS),
            # beside its bowl, not in front of it
            S(red_block=(RB[0] + FRONT, RB[1], T), blue_block=(BB[0], BB[1] - FRONT, T), **BOWLS),
            # in its bowl
            S(red_block=(*RB, IN), blue_block=(BB[0], BB[1] - FRONT, T), **BOWLS),
        ],
    ),
    "h2-red-in-front-of-left-bowl": (
        [S(red_block=(RB[0], RB[1] - FRONT, T), green_block=(0.0, -0.6, T), **BOWLS)],
        [
            S(red_block=(BB[0], BB[1] - FRONT, T), green_block=(0.0, -0.6, T), **BOWLS),  # the right bowl
            S(red_block=(RB[0], RB[1] - 0.2, T), green_block=(0.0, -0.6, T), **BOWLS),  # in front, not next to
        ],
    ),
    "h2-green-in-right-bowl": (
        [S(green_block=(*BB, IN), red_block=(0.0, -0.6, T), **BOWLS)],
        [S(green_block=(*RB, IN), red_block=(0.0, -0.6, T), **BOWLS)],
    ),
    "h2-one-in-every-bowl": (
        [S(red_block=(*RB, IN), green_block=(*BB, IN), cyan_block=(0.0, -0.6, T), **BOWLS)],
        [
            # two blocks in one bowl, the other bowl empty
            S(red_block=(*RB, IN), green_block=(*RB, IN + UP), cyan_block=(0.0, -0.6, T), **BOWLS),
            # one in each, but the extra block stacked on the table
            S(red_block=(*RB, IN), green_block=(*BB, IN), cyan_block=(0.0, -0.6, T), pink_block=(0.0, -0.6, T + UP),
              **BOWLS),
        ],
    ),
    "h2-all-but-green-in-bowls": (
        [S(red_block=(*RB, IN), cyan_block=(*BB, IN), green_block=(0.0, -0.6, T), **BOWLS)],
        [
            S(red_block=(*RB, IN), cyan_block=(*BB, IN), green_block=(*BB, IN + UP), **BOWLS),  # green in too
            S(red_block=(*RB, IN), cyan_block=(0.1, -0.6, T), green_block=(0.0, -0.7, T), **BOWLS),  # one left out
        ],
    ),
    "h2-alphabetical-tower": (
        [S(blue_block=(0.0, -0.5, T), green_block=(0.0, -0.5, T + UP), red_block=(0.0, -0.5, T + 2 * UP))],
        [
            S(blue_block=(0.0, -0.5, T), red_block=(0.0, -0.5, T + UP), green_block=(0.0, -0.5, T + 2 * UP)),
            S(blue_block=(0.0, -0.5, T), green_block=(0.0, -0.5, T + UP), red_block=(0.2, -0.5, T)),
        ],
    ),
    "h2-tower-in-middle": (
        [S(red_block=(0.01, -0.5, T), green_block=(0.01, -0.5, T + UP), **BOWLS)],
        [S(red_block=(0.25, -0.75, T), green_block=(0.25, -0.75, T + UP), **BOWLS)],  # in a corner
    ),
    "h2-purple-in-bowl-leave-rest": (
        [S(purple_block=(*RB, IN), red_block=(0.0, -0.6, T), green_block=(0.2, -0.7, T), **BOWLS)],
        [
            # the purple block is in, but another block was stacked
            S(purple_block=(*RB, IN), red_block=(0.0, -0.6, T), green_block=(0.0, -0.6, T + UP), **BOWLS),
            # and another block put in a bowl too
            S(purple_block=(*RB, IN), red_block=(*BB, IN), green_block=(0.2, -0.7, T), **BOWLS),
        ],
    ),
    "h2-towers-of-two": (
        [S(red_block=(0, -0.5, T), green_block=(0, -0.5, T + UP), cyan_block=(0.2, -0.6, T),
           pink_block=(0.2, -0.6, T + UP))],
        [S(red_block=(0, -0.5, T), green_block=(0, -0.5, T + UP), cyan_block=(0, -0.5, T + 2 * UP),
           pink_block=(0.2, -0.6, T))],
    ),
    "h2-one-left-rest-right": (
        [S(red_block=(*RB, IN), green_block=(*BB, IN), cyan_block=(*BB, IN + UP), **BOWLS)],
        [
            S(red_block=(*BB, IN), green_block=(*RB, IN), cyan_block=(*RB, IN + UP), **BOWLS),  # the other way round
            S(red_block=(*RB, IN), green_block=(*BB, IN), cyan_block=(0.0, -0.6, T), **BOWLS),  # one left out
        ],
    ),
    "h2-spread-along-front-edge": (
        [S(red_block=(-0.2, -0.75, T), green_block=(0.0, -0.74, T), cyan_block=(0.2, -0.73, T))],
        [
            S(red_block=(-0.2, -0.75, T), green_block=(-0.148, -0.75, T), cyan_block=(0.2, -0.73, T)),  # touching
            S(red_block=(-0.2, -0.75, T), green_block=(0.0, -0.6, T), cyan_block=(0.2, -0.73, T)),  # not at the edge
        ],
    ),
    "h2-warm-cool-pairs-in-bowls": (
        [S(red_block=(*RB, IN), cyan_block=(*RB, IN + UP), orange_block=(*BB, IN), green_block=(*BB, IN + UP),
           **BOWLS)],
        [S(red_block=(*RB, IN), orange_block=(*RB, IN + UP), cyan_block=(*BB, IN), green_block=(*BB, IN + UP),
           **BOWLS)],
    ),
    "h2-all-but-yellow-tower-yellow-in-bowl": (
        [S(yellow_block=(*RB, IN), red_block=(0, -0.6, T), green_block=(0, -0.6, T + UP), **BOWLS)],
        [
            S(yellow_block=(0, -0.6, T + 2 * UP), red_block=(0, -0.6, T), green_block=(0, -0.6, T + UP), **BOWLS),
            S(yellow_block=(*RB, IN), red_block=(0, -0.6, T), green_block=(0.2, -0.6, T), **BOWLS),
        ],
    ),
}


def test_boundary_cases_cover_at_least_six_intentions():
    assert len(BOUNDARY) >= 6 and set(BOUNDARY) <= set(NAMES)


@pytest.mark.parametrize("name", sorted(BOUNDARY))
def test_boundary_states(name):
    it = resolve(name)
    good, bad = BOUNDARY[name]
    for state in good:
        assert it.satisfied(state), (name, state)
        assert it.score(state) == 1.0
    for state in bad:
        assert not it.satisfied(state), (name, state)
        assert 0.0 <= it.score(state) < 1.0
        # and the oracle plans from states no layout would produce, too
        plan = it.plan(state)
        assert plan is not None, (name, state)
        assert it.satisfied(execute(state, plan)[-1]), (name, state, plan)


# --- moving away ------------------------------------------------------------------------------

SCENE = S(purple_block=(-0.05, -0.6, T), red_block=(0.1, -0.45, T), green_block=(0.2, -0.7, T), **BOWLS)


def away(name, state, step):
    after, failure = apply_skill(state, step)
    assert failure is None, failure
    return resolve(name).step_moves_away(state, after, step), after


def test_leave_everything_else_means_any_other_move_is_away():
    assert not away("h2-purple-in-bowl-leave-rest", SCENE, PutIn(block="purple block", bowl="red bowl"))[0]
    assert away("h2-purple-in-bowl-leave-rest", SCENE, PutAt(block="red block", position=(0.0, -0.5)))[0]
    assert away("h2-purple-in-bowl-leave-rest", SCENE, PutOn(block="purple block", target="red block"))[0]


def test_building_a_row_is_progress_and_a_misplaced_block_is_away():
    back = SCENE.moved("red block", (0.0, -0.25, T))
    moved, s1 = away("h2-row-along-back-edge", back, PutNextTo(block="green block", target="red block", side="right"))
    assert not moved
    assert away("h2-row-along-back-edge", s1, PutOn(block="purple block", target="green block"))[0]
    assert away("h2-row-along-back-edge", s1, PutNextTo(block="purple block", target="green block", side="front"))[0]


def test_tower_order_moves():
    tower = S(blue_block=(0.0, -0.5, T), green_block=(0.1, -0.6, T), red_block=(-0.1, -0.6, T))
    moved, s1 = away("h2-alphabetical-tower", tower, PutOn(block="green block", target="blue block"))
    assert not moved
    assert away("h2-alphabetical-tower", tower, PutOn(block="red block", target="blue block"))[0]
    assert not away("h2-alphabetical-tower", s1, PutOn(block="red block", target="green block"))[0]


def test_the_suite_is_written_with_the_world_and_intention_helpers_only():
    """No goal vocabulary (learners/) and no other suite: else its coverage would be true by construction."""
    import ast
    from pathlib import Path

    import activeintent.suites.heldout2 as module

    tree = ast.parse(Path(module.__file__).read_text())
    imported = [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    imported += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    ours = [m for m in imported if m.startswith("activeintent")]
    assert ours and all(m.startswith(("activeintent.world", "activeintent.intentions.")) for m in ours), ours
    assert not any(m.startswith(("activeintent.learners", "activeintent.bench")) for m in imported), imported
