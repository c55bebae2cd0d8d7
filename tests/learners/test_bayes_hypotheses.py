"""The hypothesis space: size, distinctness, planners, prior, and the named intentions in it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from activeintent.learners.bayes.hypotheses import (
    enumerate_hypotheses,
    hypothesis_space,
    log_prior,
    random_scene,
)
from activeintent.world import WorldState, apply_plan, layout


@pytest.fixture(scope="module")
def hyps():
    return hypothesis_space()


def test_at_least_200_distinct_hypotheses(hyps):
    assert len(hyps) >= 200
    assert len({h.name for h in hyps}) == len(hyps)
    assert len({h.description for h in hyps}) == len(hyps)
    # deduplication merged some generated ones, never added any
    assert len(hyps) <= len(enumerate_hypotheses())


def test_prior_is_a_normalised_description_length_prior(hyps):
    lp = log_prior(hyps)
    assert np.exp(lp).sum() == pytest.approx(1.0)
    bits = np.array([h.bits for h in hyps])
    # P(h) = 2^-L(h) up to normalisation: log-prior differences are bit differences
    assert (lp[0] - lp[-1]) == pytest.approx((bits[-1] - bits[0]) * math.log(2))
    by_name = {h.name: h for h in hyps}
    assert by_name["all:tower"].bits < by_name["all:tower-on[red]"].bits
    assert by_name["all:tower"].bits < by_name["warm:tower+cool:in-any-bowl"].bits


def plan_failure(h, state) -> str | None:
    """Why ``h``'s plan from ``state`` does not deliver ``h`` (None: it does)."""
    plan = h.plan(state)
    if plan is None:
        return "no plan"
    states, fails = apply_plan(state, plan)
    end = states[-1] if states else state
    if any(fails) or not h.satisfied(end):
        return "plan does not satisfy"
    return None


# A fixed bank of seeded scenes and layouts on which every hypothesis is checked.
BANK_SCENES = 30


def test_every_planner_satisfies_its_hypothesis_in_every_scene_it_calls_feasible(hyps):
    """Per hypothesis, no tolerance: in each scene the hypothesis calls feasible (two drawn for
    it, and each scene of a fixed bank that it calls feasible) its planner delivers it."""
    rng = np.random.default_rng(7)
    bank = [random_scene(rng) for _ in range(BANK_SCENES)]
    bank = [(scene, WorldState(positions=layout(scene, 5000 + k))) for k, scene in enumerate(bank)]
    failures = []
    for i, h in enumerate(hyps):
        mine = [h.sample_scene(rng) for _ in range(2)]
        cases = [(scene, WorldState(positions=layout(scene, 100 * i + k))) for k, scene in enumerate(mine)]
        cases += [(scene, state) for scene, state in bank if h.feasible(scene)]
        for scene, state in cases:
            if (why := plan_failure(h, state)) is not None:
                failures.append((h.name, str(scene), why))
    assert not failures, failures
    assert sum(h.feasible(scene) for h in hyps for scene, _ in bank) > 10 * len(hyps) // 2


def test_random_scenes_have_three_to_five_objects():
    rng = np.random.default_rng(0)
    for _ in range(50):
        scene = random_scene(rng)
        assert 3 <= len(scene.objects) <= 5 and scene.blocks and scene.bowls


def test_hypotheses_are_intentions_with_working_step_checks(hyps):
    from activeintent.intentions.base import Intention
    from activeintent.world import PutIn, PutOn

    by_name = {h.name: h for h in hyps}
    assert all(isinstance(h, Intention) for h in hyps)
    state = WorldState(positions=layout(random_scene(np.random.default_rng(1)), 0))
    blocks, bowls = state.blocks, state.bowls
    step = PutOn(block=blocks[0], target=blocks[1])
    after, _ = apply_plan(state, [step])
    assert not by_name["all:tower"].step_moves_away(state, after[-1], step)
    assert by_name["all:row"].step_moves_away(state, after[-1], step)
    step = PutIn(block=blocks[0], bowl=bowls[0])
    after, _ = apply_plan(state, [step])
    assert by_name["all:in-any-bowl"].step_moves_away(state, after[-1], step) is False
    assert by_name["all:tower"].step_moves_away(state, after[-1], step)


@pytest.mark.slow
def test_every_named_intention_has_an_agreeing_hypothesis(hyps):
    """For each built-in intention some hypothesis has the same satisfied() on many states:
    initial layouts, the intention's plans and other hypotheses' plans in its feasible scenes."""
    from activeintent.intentions.registry import all_intentions

    for intention in all_intentions():
        states = agreement_states(intention, hyps, n_scenes=5, seed=3)
        truth = [intention.satisfied(s) for s in states]
        assert any(truth) and not all(truth)
        match = [h for h in hyps if all(h.satisfied(s) == t for s, t in zip(states, truth, strict=True))]
        assert match, f"no hypothesis agrees with {intention.name}"


def agreement_states(intention, hyps, n_scenes: int = 6, seed: int = 0) -> list:
    """States to compare an intention with hypotheses: initial layouts of scenes feasible for
    it, its own plan's outcome, and the outcomes of the feasible hypotheses' plans."""
    import numpy as np

    from activeintent.world import WorldState, apply_plan, layout

    rng = np.random.default_rng(seed)
    out = []
    for i in range(n_scenes):
        scene = intention.sample_scene(rng)
        state = WorldState(positions=layout(scene, seed * 100 + i))
        out.append(state)
        for plan in [intention.plan(state)] + [h.plan(state) for h in hyps if h.feasible(scene)]:
            if plan:
                states, _ = apply_plan(state, plan)
                out.append(states[-1])
    return out


@pytest.mark.parametrize("name, objects, seed", [
    ("all:region[bottom right corner]", ["cyan block", "purple block", "red block", "pink bowl", "yellow bowl"], 1113),
    ("warm:region[bottom right corner]", ["orange block", "yellow block", "red bowl", "green bowl", "brown bowl"], 1344),
])
def test_a_bowl_in_a_corner_cell_leaves_room_for_the_blocks(hyps, name, objects, seed):
    """A bowl covered most of the coarse grid points of the corner cell: the planner found no
    plan although the scene is feasible (there is room between the grid points)."""
    from activeintent.world import Scene

    h = {h.name: h for h in hyps}[name]
    scene = Scene(objects=objects)
    state = WorldState(positions=layout(scene, seed))
    assert h.feasible(scene)
    assert plan_failure(h, state) is None


def _states_and_turned(seed: int, n: int, first_layout: int):
    """``n`` random scenes laid out: (scene, state, the same positions in reverse order)."""
    rng = np.random.default_rng(seed)
    for k in range(n):
        scene = random_scene(rng)
        state = WorldState(positions=layout(scene, first_layout + k))
        yield scene, state, WorldState(positions=dict(reversed(list(state.positions.items()))))


def test_kept_plans_are_the_plans_of_that_state_and_variant_count(hyps):
    """Hypothesis.plans keeps its answers: asked again (variants 1, then all, in either order;
    the same objects in another order) it gives what a fresh planning gives."""
    checked = 0
    for scene, state, turned in _states_and_turned(11, 12, 700):
        for h in hyps:
            if not h.feasible(scene):
                continue
            n = max(c.leaf.variants for c in h.clauses)
            for s in (state, turned, state):
                assert h.plans(s, variants=1) == h._plans(s, 1)
                assert h.plans(s) == h._plans(s, n)
            checked += n > 1 and len(h._plans(state, n)) > 1
    assert checked > 20  # hypotheses whose variants give more than one plan were among them


def test_kept_predictions_are_those_of_that_state_and_plan(hyps):
    """candidates.predict keeps its τ: asked again for a plan (the same objects in another
    order, a prefix of the plan) it gives what the symbolic world model gives now."""
    from activeintent.envs.symbolic import symbolic_trajectory
    from activeintent.learners.bayes.candidates import predict

    checked = 0
    for _, state, turned in _states_and_turned(12, 10, 900):
        for h in hyps[:40]:
            for plan in h.plans(state)[:2]:
                for s, p in ((state, plan), (turned, plan), (state, plan[:1]), (state, plan)):
                    got, fresh = predict(s, p), symbolic_trajectory(s.scene, s, p)
                    assert got.plan == list(p) and got.traj.object_names == fresh.object_names
                    assert got.traj.outcome == fresh.outcome
                    assert np.array_equal(got.traj.object_poses, fresh.object_poses)
                    checked += len(p) > 1
    assert checked > 50
