"""Each intention judged against its own one-sentence description on hand-made boundary
states: what a person reading the sentence would say about the state, the score, a step, and
whether the scene allows the intention at all (with a property test over many sampled scenes)."""

from __future__ import annotations

import numpy as np
import pytest

from activeintent.intentions import all_intentions, get_intention
from activeintent.intentions.placement import is_warm
from activeintent.protocol import sample_test_scene
from activeintent.suites.dev import dev_intentions
from activeintent.world import (
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    Scene,
    WorldState,
    apply_plan,
    apply_skill,
    layout,
    relations,
)
from activeintent.world.skills import TABLE_POSITIONS
from helpers import BOWLS, IN, UP, S, T

DEV = {it.name: it for it in dev_intentions()}


def intention(name: str):
    return DEV[name] if name in DEV else get_intention(name)


def reaches(name: str, state: WorldState) -> bool:
    """The intention's own plan from ``state`` runs and ends in a state it accepts."""
    it = intention(name)
    plan = it.plan(state)
    if plan is None:
        return False
    states, failures = apply_plan(state, plan)
    return failures == [None] * len(plan) and it.satisfied(states[-1] if states else state)


def away(name: str, state: WorldState, step) -> bool:
    after, failure = apply_skill(state, step)
    assert failure is None, failure
    return intention(name).step_moves_away(state, after, step)


# --- stack -----------------------------------------------------------------------------------

PILED_IN_BOWL = S(red_block=(-0.2, -0.3, IN), blue_block=(-0.2, -0.3, IN + UP), **BOWLS)
TOWER_ON_TABLE = S(red_block=(0, -0.5, T), blue_block=(0, -0.5, T + UP), **BOWLS)


def test_stack_blocks_piled_in_a_bowl_are_not_a_tower():
    """"Stack all the blocks into a single tower." Two blocks put one after the other into the
    same bowl lie on each other (world.relations says `on`, and both are in the bowl), but they
    are piled in the bowl, not stacked into a tower: "all blocks in one bowl" must not pass."""
    rel = relations(PILED_IN_BOWL)
    assert rel.below("blue block") == "red block" and rel.in_bowl("red block") == "red bowl"
    stack = get_intention("stack")
    assert not stack.satisfied(PILED_IN_BOWL)
    assert stack.score(PILED_IN_BOWL) < 1.0
    assert stack.satisfied(TOWER_ON_TABLE) and stack.score(TOWER_ON_TABLE) == pytest.approx(1.0)
    # The same pile judged by "all blocks in one bowl" is satisfied: the two must differ.
    assert get_intention("one-bowl").satisfied(PILED_IN_BOWL)
    assert reaches("stack", PILED_IN_BOWL)  # the plan sets a block down and stacks on it


def test_stack_score_counts_only_a_tower_standing_on_the_table():
    """"Stack all the blocks into a single tower." Two blocks piled in a bowl and one on the
    table: the only tower is the lone block on the table (1 of 3)."""
    state = PILED_IN_BOWL.moved("green block", (0.0, -0.6, T))
    assert get_intention("stack").score(state) == pytest.approx(1 / 3)


def test_stack_putting_a_block_on_a_pile_in_a_bowl_moves_away():
    """"Stack all the blocks into a single tower." Putting a block onto a block lying in a bowl
    piles it in the bowl; a person wanting a tower stops that. Onto a block on the table: fine."""
    state = S(red_block=(-0.2, -0.3, IN), blue_block=(0.0, -0.6, T), green_block=(0.1, -0.7, T), **BOWLS)
    assert away("stack", state, PutOn(block="blue block", target="red block"))
    assert not away("stack", state, PutOn(block="blue block", target="green block"))
    assert away("stack", state, PutIn(block="blue block", bowl="blue bowl"))


def test_stack_tower_next_to_a_bowl_and_a_tower_with_a_stray_block():
    """"Stack all the blocks into a single tower." A tower standing on the table right beside a
    bowl is a tower; a tower plus one block left on the table is not a single tower of all."""
    beside = S(red_block=(-0.2 + 0.097, -0.3, T), blue_block=(-0.2 + 0.097, -0.3, T + UP), **BOWLS)
    assert get_intention("stack").satisfied(beside)
    stray = TOWER_ON_TABLE.moved("green block", (0.052, -0.5, T))
    assert not get_intention("stack").satisfied(stray)
    assert get_intention("stack").score(stray) == pytest.approx(2 / 3)


# --- two-towers ------------------------------------------------------------------------------

TWO_PILES_IN_BOWLS = S(red_block=(-0.2, -0.3, IN), blue_block=(-0.2, -0.3, IN + UP),
                       green_block=(0.2, -0.3, IN), cyan_block=(0.2, -0.3, IN + UP), **BOWLS)


def test_two_towers_piles_in_bowls_are_not_towers():
    """"Stack the blocks into two towers of (nearly) equal height." Two blocks piled in each of
    two bowls is "two in each bowl", not two towers; one pile in a bowl and a real tower on the
    table is one tower."""
    two = get_intention("two-towers")
    assert not two.satisfied(TWO_PILES_IN_BOWLS)
    assert two.score(TWO_PILES_IN_BOWLS) == pytest.approx(0.0)
    one_real = TWO_PILES_IN_BOWLS.moved("green block", (0.0, -0.6, T)).moved("cyan block", (0.0, -0.6, T + UP))
    assert not two.satisfied(one_real)
    assert two.score(one_real) == pytest.approx(0.5)
    real = one_real.moved("red block", (-0.1, -0.7, T)).moved("blue block", (-0.1, -0.7, T + UP))
    assert two.satisfied(real)
    assert reaches("two-towers", TWO_PILES_IN_BOWLS) and reaches("two-towers", one_real)


def test_two_towers_putting_a_block_on_a_pile_in_a_bowl_moves_away():
    """"Stack the blocks into two towers of (nearly) equal height." Topping up a pile in a bowl
    builds no tower."""
    state = S(red_block=(-0.2, -0.3, IN), blue_block=(0.0, -0.6, T), green_block=(0.1, -0.7, T),
              cyan_block=(-0.1, -0.7, T), **BOWLS)
    assert away("two-towers", state, PutOn(block="blue block", target="red block"))
    assert not away("two-towers", state, PutOn(block="blue block", target="green block"))


# --- dev-column-along-left-edge ------------------------------------------------------------

def column_at(x: float, n: int = 3, **extra) -> WorldState:
    names = ["red_block", "blue_block", "green_block", "cyan_block"][:n]
    return S(**{b: (x, -0.5 - 0.052 * i, T) for i, b in enumerate(names)}, **extra)


def test_column_along_the_left_edge_means_near_that_edge():
    """"Line the blocks up front to back in one straight column along the left edge of the
    table." A column 6-10 cm from the left edge runs along it; one in the left third but 11 cm
    from the table's middle line (19 cm from the edge) does not, nor does one in the middle."""
    column = intention("dev-column-along-left-edge")
    assert column.satisfied(column_at(-0.26)) and column.satisfied(column_at(-0.2))
    assert not column.satisfied(column_at(-0.11))
    assert column.score(column_at(-0.11)) < 1.0
    assert not column.satisfied(column_at(0.0))
    assert reaches("dev-column-along-left-edge", column_at(-0.11, **BOWLS))


def test_column_along_the_left_edge_with_a_gap_or_a_block_in_a_bowl():
    """"Line the blocks up front to back in one straight column along the left edge of the
    table." A column with a gap is two pieces; a block in a bowl by the edge is not in it."""
    column = intention("dev-column-along-left-edge")
    gap = column_at(-0.25).moved("green block", (-0.25, -0.75, T))
    assert not column.satisfied(gap) and column.score(gap) == pytest.approx(2 / 3)
    bowl = dict(red_bowl=(-0.22, -0.3, 0))
    in_bowl = column_at(-0.25, n=2, **bowl).moved("green block", (-0.22, -0.3, IN))
    assert not column.satisfied(in_bowl)


def test_column_step_into_the_left_third_but_away_from_the_edge_moves_away():
    """"Line the blocks up front to back in one straight column along the left edge of the
    table." Setting a block down 19 cm from the left edge puts it where no such column goes."""
    state = S(red_block=(-0.25, -0.5, T), blue_block=(0.1, -0.6, T), green_block=(0.2, -0.3, T))
    assert away("dev-column-along-left-edge", state, PutAt(block="blue block", position=(-0.11, -0.6)))
    assert not away("dev-column-along-left-edge", state,
                    PutNextTo(block="blue block", target="red block", side="front"))


# --- feasible(scene) is exactly right -------------------------------------------------------
#
# feasible(scene) means "the intention can be shown and satisfied in this scene" (Intention
# docs): every feasible scene must be satisfiable from any layout, and an infeasible scene must
# be unsatisfiable, or one where the sentence cannot be shown because the scene lacks what it
# talks about (listed here, each with the reason).


def _warm(scene) -> int:
    return sum(is_warm(b) for b in scene.blocks)


UNSHOWABLE = {
    # a single block makes no row, tower or group, and is not "together" with anything
    "align": lambda s: len(s.blocks) < 2,
    "align-vertical": lambda s: len(s.blocks) < 2,
    "stack": lambda s: len(s.blocks) < 2,
    "one-bowl": lambda s: len(s.blocks) < 2,
    "dev-gather-in-one-corner": lambda s: len(s.blocks) < 2,
    # two towers of at least two blocks each need four
    "two-towers": lambda s: len(s.blocks) < 4,
    # one of the sentence's two colour classes is missing
    "warm-in-bowls-cool-stacked": lambda s: _warm(s) in (0, len(s.blocks)),
    "warm-left-cool-right": lambda s: _warm(s) in (0, len(s.blocks)),
    "dev-warm-on-cool": lambda s: _warm(s) == 0,
    "dev-warm-and-cool-groups": lambda s: len(s.blocks) < 3 or _warm(s) in (0, len(s.blocks)),
}
EVERY = [*all_intentions(), *dev_intentions()]
ODD_SCENES = [
    ["red bowl", "blue bowl", "green bowl"],
    ["red block", "red bowl", "blue bowl"],
    ["red block", "blue block", "green block"],
    ["red block", "orange block", "yellow block", "red bowl"],
    ["blue block", "green block", "cyan block", "gray block", "blue bowl"],
]


def _scenes(it) -> list[Scene]:
    scenes = [sample_test_scene(np.random.default_rng(100 + i)) for i in range(40)]
    scenes += [it.sample_scene(np.random.default_rng(200 + i)) for i in range(10)]
    return scenes + [Scene(objects=o) for o in ODD_SCENES]


def _random_states(state: WorldState, rng: np.random.Generator, steps: int) -> list[WorldState]:
    out = [state]
    for _ in range(steps):
        block = str(rng.choice(state.blocks))
        kind = int(rng.integers(4))
        if kind == 0 and state.bowls:
            step = PutIn(block=block, bowl=str(rng.choice(state.bowls)))
        elif kind == 1:
            step = PutOn(block=block, target=str(rng.choice(state.blocks)))
        elif kind == 2:
            step = PutNextTo(block=block, target=str(rng.choice(state.names)),
                             side=str(rng.choice(["left", "right", "front", "behind", "nearest"])))
        else:
            step = PutAt(block=block, position=str(rng.choice(list(TABLE_POSITIONS))))
        state, _ = apply_skill(state, step)
        out.append(state)
    return out


def _goal_states(state: WorldState) -> list[WorldState]:
    """Where the plans of every library and dev intention lead from ``state``."""
    out = []
    for other in EVERY:
        plan = other.plan(state)
        if plan is not None:
            states, failures = apply_plan(state, plan)
            if not any(failures):
                out.append(states[-1] if states else state)
    return out


@pytest.mark.parametrize("it", EVERY, ids=lambda i: i.name)
def test_feasible_scenes_are_satisfiable_and_infeasible_ones_are_not(it):
    """Each intention's sentence against `feasible`: on test scenes (protocol.sample_test_scene),
    its own sampled scenes and a few odd ones, a feasible scene is satisfied by the intention's
    plan from several layouts, and an infeasible one admits no satisfying state among the goal
    states of all intentions and random moves, unless the scene cannot show the sentence."""
    unshowable = UNSHOWABLE.get(it.name, lambda s: False)
    for i, scene in enumerate(_scenes(it)):
        if it.feasible(scene):
            assert not unshowable(scene), (it.name, scene)
            for seed in (i, i + 1000, i + 2000):
                state = WorldState(positions=layout(scene, seed))
                assert reaches(it.name, state), (it.name, scene, seed)
        elif scene.blocks and not unshowable(scene):
            state = WorldState(positions=layout(scene, i))
            bank = _goal_states(state) + _random_states(state, np.random.default_rng(i), 20)
            assert not any(it.satisfied(s) for s in bank), (it.name, scene)
        else:
            state = WorldState(positions=layout(scene, i))
            it.plan(state)  # may be None; must not crash
            assert 0.0 <= it.score(state) <= 1.0


@pytest.mark.parametrize("it", EVERY, ids=lambda i: i.name)
def test_satisfied_exactly_when_the_score_is_full(it):
    """A state is satisfied exactly when its score is 1, on random states of feasible scenes."""
    rng = np.random.default_rng(7)
    for i, scene in enumerate(_scenes(it)[:25]):
        if not it.feasible(scene):
            continue
        for state in _random_states(WorldState(positions=layout(scene, i)), rng, 12):
            score = it.score(state)
            assert 0.0 <= score <= 1.0
            assert it.satisfied(state) == (score >= 1.0 - 1e-9), (it.name, state, score)


# --- more boundary states, one sentence each --------------------------------------------------

RIM = 0.06  # a block centre between the bowl's inner (5.5 cm) and outer (6.5 cm) radius
BESIDE = 0.097  # where PutNextTo leaves a block beside a bowl


def test_align_row_with_a_gap_and_a_block_by_a_bowl():
    """"Align all the blocks horizontally: one straight left-to-right row on the table, each
    block next to its neighbour, none stacked or in a bowl." A row with a 13 cm gap is two
    pieces (2 of 3); a row whose end block touches a bowl is still a row; a block in a bowl
    at the row's end is not in it."""
    align = get_intention("align")
    gap = S(red_block=(-0.1, -0.5, T), blue_block=(-0.048, -0.5, T), green_block=(0.13, -0.5, T))
    assert not align.satisfied(gap) and align.score(gap) == pytest.approx(2 / 3)
    by_bowl = S(red_block=(-0.2 + BESIDE, -0.3, T), blue_block=(-0.2 + BESIDE + 0.052, -0.3, T), **BOWLS)
    assert align.satisfied(by_bowl)
    in_bowl = by_bowl.moved("green block", (0.2, -0.3, IN))
    assert not align.satisfied(in_bowl) and align.score(in_bowl) == pytest.approx(2 / 3)
    assert away("align", by_bowl.moved("green block", (0.1, -0.6, T)),
                PutIn(block="green block", bowl="blue bowl"))


def test_already_satisfied_starts_need_no_steps_and_breaking_them_moves_away():
    """"Stack all the blocks into a single tower." / "Put each block in the bowl of the same
    colour." A start that already realises the sentence needs an empty plan, and taking a
    block out of it is a move away."""
    assert get_intention("stack").plan(TOWER_ON_TABLE) == []
    assert away("stack", TOWER_ON_TABLE, PutAt(block="blue block", position="bottom left corner"))
    matched = S(red_block=(-0.2, -0.3, IN), blue_block=(0.2, -0.3, IN), **BOWLS)
    assert get_intention("color-match").plan(matched) == []
    assert away("color-match", matched, PutAt(block="red block", position="middle"))


def test_color_match_wrong_bowl_rim_and_beside():
    """"Put each block in the bowl of the same colour." A block in the other bowl, beside its
    bowl, or with its centre over the rim (not inside the inner radius) is not in its bowl; a
    block lying on another block in its own bowl is."""
    match = get_intention("color-match")
    assert not match.satisfied(S(red_block=(0.2, -0.3, IN), blue_block=(-0.2, -0.3, IN), **BOWLS))
    beside = S(red_block=(-0.2 + BESIDE, -0.3, T), blue_block=(0.2, -0.3, IN), **BOWLS)
    assert not match.satisfied(beside) and match.score(beside) == pytest.approx(0.5)
    rim = S(red_block=(-0.2 + RIM, -0.3, T), blue_block=(0.2, -0.3, IN), **BOWLS)
    assert not match.satisfied(rim)
    on_other = S(green_block=(-0.2, -0.3, IN), red_block=(-0.2, -0.3, IN + UP), **BOWLS)
    assert match.wanted(on_other, relations(on_other), "red block")


def test_next_to_same_colour_bowl_beside_in_and_stacked():
    """"Put each block on the table next to (not in) the bowl of its own colour." Beside its
    own bowl: yes; in it: no; beside the other bowl: no; on top of a block that stands beside
    its bowl: not on the table."""
    nxt = get_intention("next-to-same-color-bowl")
    assert nxt.satisfied(S(red_block=(-0.2 + BESIDE, -0.3, T), **BOWLS))
    assert not nxt.satisfied(S(red_block=(-0.2, -0.3, IN), **BOWLS))
    assert not nxt.satisfied(S(red_block=(0.2 - BESIDE, -0.3, T), **BOWLS))
    stacked = S(red_block=(-0.2 + BESIDE, -0.3, T + UP), green_block=(-0.2 + BESIDE, -0.3, T), **BOWLS)
    assert not nxt.wanted(stacked, relations(stacked), "red block")


def test_one_bowl_and_one_block_per_bowl_on_split_and_shared_bowls():
    """"Put all the blocks together in one bowl (any bowl)." / "Put each block alone in its own
    bowl, whatever the colours." One block in each of two bowls satisfies the second and half
    of the first; both in one bowl the other way round."""
    split = S(red_block=(-0.2, -0.3, IN), green_block=(0.2, -0.3, IN), **BOWLS)
    shared = S(red_block=(-0.2, -0.3, IN), green_block=(-0.2, -0.3, IN + UP), **BOWLS)
    one, alone = get_intention("one-bowl"), get_intention("one-block-per-bowl")
    assert alone.satisfied(split) and not one.satisfied(split) and one.score(split) == pytest.approx(0.5)
    assert one.satisfied(shared) and not alone.satisfied(shared) and alone.score(shared) == 0.0


def test_warm_in_bowls_cool_stacked_tower_must_stand_on_the_table():
    """"Put the warm-coloured blocks in bowls and stack the cool-coloured blocks into one tower
    on the table." Cool blocks piled in a bowl are not a tower on the table; a warm block on
    top of the cool tower is not in a bowl."""
    it = get_intention("warm-in-bowls-cool-stacked")
    piled = S(red_block=(0.2, -0.3, IN), blue_block=(-0.2, -0.3, IN), green_block=(-0.2, -0.3, IN + UP), **BOWLS)
    assert not it.satisfied(piled)
    on_top = S(blue_block=(0, -0.6, T), green_block=(0, -0.6, T + UP), red_block=(0, -0.6, T + 2 * UP), **BOWLS)
    assert not it.satisfied(on_top) and it.score(on_top) == pytest.approx(2 / 3)


def test_regions_blocks_in_bowls_and_stacked_blocks():
    """"Move all the blocks onto the left half of the table (on the table, not in bowls)." /
    "Put each block on the table in a different corner of the table." A block in a bowl on the
    left half is not on the table; of two blocks stacked in one corner only the upper one is
    misplaced (moving it to a free corner completes the sentence)."""
    left = get_intention("blocks-left-half")
    assert not left.satisfied(S(red_block=(-0.2, -0.3, IN), blue_block=(-0.1, -0.6, T), **BOWLS))
    corners = get_intention("blocks-in-corners")
    stacked = S(red_block=(-0.25, -0.25, T), blue_block=(-0.25, -0.25, T + UP), green_block=(0.25, -0.75, T))
    assert not corners.satisfied(stacked) and corners.score(stacked) == pytest.approx(2 / 3)


def test_empty_scene_satisfies_nothing():
    """Every sentence is about "the blocks": a table with bowls only is not feasible, satisfies
    nothing and has no plan."""
    empty = S(**BOWLS, green_bowl=(0.0, -0.6, 0))
    for it in EVERY:
        assert not it.feasible(empty.scene), it.name
        assert not it.satisfied(empty) and it.score(empty) == 0.0 and it.plan(empty) is None, it.name


def test_dev_tower_beside_a_bowl_and_warm_on_cool():
    """"Stack all the blocks into one tower standing on the table right next to a bowl." /
    "Put each warm-coloured block on top of a cool-coloured block." A pile in a bowl does not
    stand next to it; a warm block on a cool block that lies in a bowl is on top of it."""
    beside = intention("dev-tower-beside-a-bowl")
    assert not beside.satisfied(PILED_IN_BOWL)
    assert beside.satisfied(S(red_block=(-0.2 + BESIDE, -0.3, T), blue_block=(-0.2 + BESIDE, -0.3, T + UP), **BOWLS))
    warm_on_cool = intention("dev-warm-on-cool")
    assert warm_on_cool.satisfied(S(blue_block=(-0.2, -0.3, IN), red_block=(-0.2, -0.3, IN + UP), **BOWLS))
    assert not warm_on_cool.satisfied(S(blue_block=(0, -0.6, T), red_block=(0.052, -0.6, T)))
