"""The paper intentions' plans, executed in the real PyBullet simulator, satisfy them."""

import numpy as np
import pytest

from activeintent.intentions import PAPER_INTENTIONS, get_intention

env_module = pytest.importorskip("activeintent.sim.env")

SEEDS = (0, 1, 2)


@pytest.fixture(scope="module")
def env():
    with env_module.TabletopEnv(env_module.SimConfig()) as e:
        yield e


@pytest.mark.slow
@pytest.mark.parametrize("name", PAPER_INTENTIONS)
@pytest.mark.parametrize("seed", SEEDS)
def test_plan_satisfies_paper_intention_in_simulator(env, name, seed):
    intention = get_intention(name)
    scene = intention.sample_scene(np.random.default_rng(seed))
    assert intention.feasible(scene)
    state = env.reset(scene, seed)
    assert not intention.satisfied(state) or intention.plan(state) == []
    plan = intention.plan(state)
    assert plan is not None
    traj = env.execute(plan)
    assert not traj.failures, [s.reason for s in traj.failures]
    assert intention.satisfied(traj.final_state), (scene, plan, traj.final_state)
    # Executing the intention's own plan never moves away from it, step by step.
    assert not any(intention.step_moves_away(s.state_before, s.state_after, s.skill) for s in traj.steps)
