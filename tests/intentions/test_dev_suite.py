"""The dev suite (suites/dev.py): sampled scenes are feasible, oracle plans reach the intention
in the symbolic world model, hand-built states are judged as a person would, and the suite
resolves everywhere an intention name is accepted."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from activeintent.intentions import INTENTION_NAMES
from activeintent.suites import SUITE_NAMES, resolve, suite, suite_of
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
)
from helpers import BOWLS, IN, UP, S, T

ROOT = Path(__file__).resolve().parents[2]
DEV = dev_intentions()
BY_NAME = {it.name: it for it in DEV}
SEEDS = range(20)



def test_ten_unique_kebab_case_names_with_one_sentence_each():
    names = [it.name for it in DEV]
    assert len(names) == 10 and len(set(names)) == 10
    assert not set(names) & set(INTENTION_NAMES)
    for it in DEV:
        assert it.name == it.name.lower() and " " not in it.name and "_" not in it.name
        assert it.description.endswith(".") and it.description.count(". ") == 0, it.description


def test_suite_lists_and_resolves_dev_names():
    assert "dev" in SUITE_NAMES
    assert suite("dev") == [it.name for it in DEV]
    for name in suite("dev"):
        assert suite_of(name) == "dev"
        assert type(resolve(name)) is type(BY_NAME[name])
    assert suite_of("align") == "paper" and suite_of("one-bowl") == "library"
    overlap = bool(set(suite("dev")) & set(suite("heldout")))  # names only, never printed
    assert not overlap, "a dev intention shares its name with a held-out one"


@pytest.mark.parametrize("intention", DEV, ids=lambda i: i.name)
def test_sampled_scenes_are_feasible_and_oracle_plans_satisfy_them(intention):
    already = 0
    for seed in SEEDS:
        scene = intention.sample_scene(np.random.default_rng(seed))
        assert isinstance(scene, Scene)
        assert 3 <= len(scene.objects) <= 5, scene
        assert intention.feasible(scene), (intention.name, scene)
        state = WorldState(positions=layout(scene, seed))
        already += intention.satisfied(state)
        plan = intention.plan(state)
        assert plan is not None, (intention.name, scene, seed)
        states, failures = apply_plan(state, plan)
        assert failures == [None] * len(plan), (intention.name, seed, failures)
        final = states[-1] if states else state
        assert intention.satisfied(final), (intention.name, scene, seed, plan)
        assert intention.score(final) == pytest.approx(1.0)
        before = state
        for step, after in zip(plan, states, strict=True):  # the oracle never moves away
            assert not intention.step_moves_away(before, after, step), (intention.name, seed, step)
            before = after
    assert already <= 3, f"{intention.name}: {already} of {len(SEEDS)} layouts already satisfy it"


@pytest.mark.parametrize("intention", DEV, ids=lambda i: i.name)
def test_sample_scene_is_deterministic(intention):
    assert intention.sample_scene(np.random.default_rng(3)) == intention.sample_scene(np.random.default_rng(3))


# (intention, states that satisfy it, states that break it)
CASES = {
    "dev-rainbow-row": (
        [S(red_block=(0, -0.5, T), yellow_block=(0.052, -0.5, T), blue_block=(0.104, -0.51, T), **BOWLS)],
        [
            S(yellow_block=(0, -0.5, T), red_block=(0.052, -0.5, T), blue_block=(0.104, -0.5, T)),  # order
            S(red_block=(0, -0.5, T), yellow_block=(0, -0.5, T + UP), blue_block=(0.2, -0.6, T)),  # stacked
            S(red_block=(0, -0.5, T), yellow_block=(0, -0.552, T), blue_block=(0, -0.604, T)),  # a column
        ],
    ),
    "dev-gather-in-one-corner": (
        [S(red_block=(-0.25, -0.75, T), blue_block=(-0.18, -0.7, T), **BOWLS)],
        [
            S(red_block=(-0.25, -0.75, T), blue_block=(0.25, -0.75, T), **BOWLS),
            S(red_block=(-0.25, -0.75, T), blue_block=(0.0, -0.5, T), green_block=(0.0, -0.5, T + UP)),
        ],
    ),
    "dev-at-most-two-per-bowl": (
        [S(red_block=(-0.2, -0.3, IN), green_block=(-0.2, -0.3, IN + UP), cyan_block=(0.2, -0.3, IN), **BOWLS)],
        [
            S(red_block=(-0.2, -0.3, IN), green_block=(-0.2, -0.3, IN + UP),
              cyan_block=(-0.2, -0.3, IN + 2 * UP), **BOWLS),
            S(red_block=(-0.2, -0.3, IN), green_block=(0.0, -0.6, T), **BOWLS),
        ],
    ),
    "dev-warm-to-warm-bowls": (
        [S(orange_block=(-0.2, -0.3, IN), green_block=(0.2, -0.3, IN), **BOWLS)],
        [
            S(orange_block=(0.2, -0.3, IN), green_block=(-0.2, -0.3, IN), **BOWLS),
            S(orange_block=(-0.2, -0.3, IN), green_block=(0.0, -0.6, T), **BOWLS),
        ],
    ),
    "dev-warm-on-cool": (
        [S(blue_block=(0, -0.5, T), red_block=(0, -0.5, T + UP), green_block=(0.2, -0.6, T))],
        [
            S(blue_block=(0, -0.5, T), red_block=(0.1, -0.6, T), green_block=(0.2, -0.6, T)),
            S(red_block=(0, -0.5, T), blue_block=(0, -0.5, T + UP), green_block=(0.2, -0.6, T)),
        ],
    ),
    "dev-blocks-together": (
        [S(red_block=(0, -0.5, T), blue_block=(0.052, -0.5, T), green_block=(0.052, -0.552, T), **BOWLS)],
        [
            S(red_block=(0, -0.5, T), blue_block=(0.052, -0.5, T), green_block=(-0.2, -0.7, T)),
            S(red_block=(0, -0.5, T), blue_block=(0.052, -0.5, T), green_block=(0.052, -0.5, T + UP)),
        ],
    ),
    "dev-blocks-around-a-bowl": (
        [S(green_block=(-0.103, -0.3, T), cyan_block=(-0.2, -0.397, T), **BOWLS)],
        [
            S(green_block=(-0.103, -0.3, T), cyan_block=(0.2, -0.397, T), **BOWLS),
            S(green_block=(-0.103, -0.3, T), cyan_block=(-0.2, -0.3, IN), **BOWLS),
        ],
    ),
    "dev-tower-beside-a-bowl": (
        [S(green_block=(-0.103, -0.3, T), cyan_block=(-0.103, -0.3, T + UP), **BOWLS)],
        [
            S(green_block=(0.0, -0.6, T), cyan_block=(0.0, -0.6, T + UP), **BOWLS),
            S(green_block=(-0.103, -0.3, T), cyan_block=(0.0, -0.6, T), **BOWLS),
        ],
    ),
    "dev-column-along-left-edge": (
        [S(red_block=(-0.2, -0.5, T), blue_block=(-0.2, -0.552, T), green_block=(-0.21, -0.604, T), **BOWLS)],
        [
            S(red_block=(0.0, -0.5, T), blue_block=(0.0, -0.552, T), green_block=(0.0, -0.604, T), **BOWLS),
            S(red_block=(-0.2, -0.5, T), blue_block=(-0.148, -0.5, T), green_block=(-0.096, -0.5, T)),
        ],
    ),
    "dev-warm-and-cool-groups": (
        [S(red_block=(-0.2, -0.6, T), orange_block=(-0.148, -0.6, T), blue_block=(0.2, -0.6, T),
           green_block=(0.2, -0.652, T), **BOWLS)],
        [
            S(red_block=(-0.2, -0.6, T), orange_block=(0.148, -0.6, T), blue_block=(0.2, -0.6, T),
              green_block=(0.2, -0.652, T)),
            S(red_block=(-0.2, -0.6, T), orange_block=(0.0, -0.75, T), blue_block=(0.2, -0.6, T),
              green_block=(0.2, -0.652, T)),
            S(red_block=(-0.2, -0.6, T), orange_block=(-0.2, -0.6, T + UP), blue_block=(0.2, -0.6, T),
              green_block=(0.2, -0.652, T)),
        ],
    ),
}


def test_every_dev_intention_has_hand_built_cases():
    assert set(CASES) == set(BY_NAME)


@pytest.mark.parametrize("name", sorted(CASES))
def test_hand_built_states(name):
    intention = BY_NAME[name]
    good, bad = CASES[name]
    for state in good:
        assert intention.satisfied(state), (name, state)
        assert intention.score(state) == pytest.approx(1.0)
        assert intention.plan(state) == []
    for state in bad:
        assert not intention.satisfied(state), (name, state)
        assert 0.0 <= intention.score(state) < 1.0
        plan = intention.plan(state)  # plans also work from states no layout would produce
        assert plan is not None, (name, state)
        states, failures = apply_plan(state, plan)
        assert failures == [None] * len(plan)
        assert intention.satisfied(states[-1])


def test_feasibility_rules():
    def feasible(name, *objects):
        return BY_NAME[name].feasible(Scene(objects=list(objects)))

    assert not feasible("dev-rainbow-row", "red block", "gray block", "red bowl")
    assert feasible("dev-rainbow-row", "red block", "cyan block", "red bowl")
    assert not feasible("dev-at-most-two-per-bowl", "red block", "blue block", "green block", "red bowl")
    assert feasible("dev-at-most-two-per-bowl", "red block", "blue block", "red bowl")
    assert not feasible("dev-warm-to-warm-bowls", "red block", "blue block", "red bowl", "orange bowl")
    assert not feasible("dev-warm-on-cool", "red block", "orange block", "blue block")
    assert not feasible("dev-tower-beside-a-bowl", "red block", "orange block", "blue block")
    assert not feasible("dev-warm-and-cool-groups", "red block", "blue block", "blue bowl")


def away(name, state, step):
    after, failure = apply_skill(state, step)
    assert failure is None, failure
    return BY_NAME[name].step_moves_away(state, after, step)


def test_moves_away():
    row = S(red_block=(-0.1, -0.6, T), yellow_block=(0.15, -0.45, T), blue_block=(0.2, -0.7, T), **BOWLS)
    assert not away("dev-rainbow-row", row, PutNextTo(block="yellow block", target="red block", side="right"))
    assert away("dev-rainbow-row", row, PutNextTo(block="yellow block", target="red block", side="left"))
    assert away("dev-rainbow-row", row, PutOn(block="yellow block", target="red block"))
    cool_warm = S(blue_block=(0, -0.5, T), red_block=(0.2, -0.6, T), green_block=(-0.2, -0.6, T))
    assert not away("dev-warm-on-cool", cool_warm, PutOn(block="red block", target="blue block"))
    assert away("dev-warm-on-cool", cool_warm, PutNextTo(block="red block", target="blue block"))
    assert away("dev-gather-in-one-corner", S(red_block=(-0.25, -0.75, T), blue_block=(-0.18, -0.7, T)),
                PutAt(block="blue block", position="top right corner"))
    bowls = S(red_block=(-0.2, -0.3, IN), green_block=(-0.2, -0.3, IN + UP), cyan_block=(0, -0.6, T), **BOWLS)
    assert away("dev-at-most-two-per-bowl", bowls, PutIn(block="cyan block", bowl="red bowl"))
    assert not away("dev-at-most-two-per-bowl", bowls, PutIn(block="cyan block", bowl="blue bowl"))
    groups = S(red_block=(-0.2, -0.6, T), orange_block=(0.0, -0.75, T), blue_block=(0.2, -0.6, T))
    assert not away("dev-warm-and-cool-groups", groups, PutNextTo(block="orange block", target="red block"))
    assert away("dev-warm-and-cool-groups", groups, PutNextTo(block="orange block", target="blue block"))


def test_run_command_accepts_a_dev_intention(tmp_path):
    res = subprocess.run(
        [sys.executable, "-m", "activeintent.cli", "run", "--method", "zero-signal", "--intention", "dev-blocks-together",
         "--env", "symbolic", "--llm", "none", "--video", "none", "--out", str(tmp_path / "run")],
        cwd=ROOT, capture_output=True, text=True, timeout=240,
    )
    assert res.returncode == 0, res.stdout[-1500:] + res.stderr[-1500:]
