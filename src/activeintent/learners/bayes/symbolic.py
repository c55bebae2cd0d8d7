"""A physics-free episode for fast checks: trajectories built from world.predict.

:func:`symbolic_trajectory` makes a :class:`Trajectory` (the same pure-data log the
simulator writes) from the symbolic world model, with fixed step timing; the simulated users
read it like a real one. :func:`run_symbolic_episode` is the episode loop of design.md §2
without the simulator, used by tests and by ``activeintent bayes-bench``.
"""

from __future__ import annotations

import time

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.learners.base import Learner, RoundRecord
from activeintent.sim.trajectory import StepRecord, Trajectory
from activeintent.world import Scene, Skill, WorldState, apply_plan, layout

STEP_SECONDS = 3.0  # simulated time per skill
REVEAL_FRACTION = 0.35  # the destination becomes evident this far into a skill
DT = 0.05


def symbolic_trajectory(scene: Scene, state: WorldState, plan: list[Skill], seed: int = 0) -> Trajectory:
    """τ for ``plan`` from ``state`` on the symbolic world model (blocks jump at step ends)."""
    states, fails = apply_plan(state, plan)
    names = list(state.positions)
    per = int(round(STEP_SECONDS / DT))
    n_ticks = per * len(plan) + 1
    poses = np.zeros((n_ticks, len(names), 7))
    poses[..., 6] = 1.0
    step_index = np.full(n_ticks, -1)
    records = []
    current = state
    poses[:, :, :3] = np.array([state.positions[n] for n in names])
    for k, (step, after, fail) in enumerate(zip(plan, states, fails, strict=True)):
        start, end = k * per, (k + 1) * per
        step_index[start:end] = k
        poses[end:, :, :3] = np.array([after.positions[n] for n in names])
        records.append(
            StepRecord(
                index=k,
                skill=step,
                start_tick=start,
                reveal_tick=start + int(round(REVEAL_FRACTION * per)),
                end_tick=end,
                ok=fail is None,
                reason=None if fail is None else fail.reason,
                state_before=current,
                state_after=after,
            )
        )
        current = after
    return Trajectory(
        scene=scene,
        seed=seed,
        dt=DT,
        object_names=names,
        object_poses=poses,
        joint_positions=np.zeros((n_ticks, 7)),
        ee_pose=np.zeros((n_ticks, 7)),
        gripper_closed=np.zeros(n_ticks, dtype=bool),
        step_index=step_index,
        steps=records,
        initial_state=state,
        final_state=current,
    )


def run_symbolic_episode(
    learner: Learner,
    intention: Intention,
    user,
    rounds: int = 5,
    seed: int = 0,
    test_scenes: int = 1,
) -> dict:
    """One episode without physics; returns success, signals used and per-query timings."""
    rng = np.random.default_rng(seed)
    signals, select_s = 0, []
    for r in range(rounds):
        t0 = time.perf_counter()
        scene = learner.design_scene(rng)
        if scene is None:
            scene = intention.sample_scene(rng)
        state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
        est = learner.estimate(scene, state)
        select_s.append(time.perf_counter() - t0)
        if est.done:
            break
        plans = est.plans or []
        trajs = [symbolic_trajectory(scene, state, p, seed) for p in plans]
        feedback = user.respond(scene, trajs)
        record = RoundRecord(index=r, scene=scene, estimate=est, plans=plans, feedback=feedback)
        learner.observe(record, trajs)
        signals += 1
    wins = []
    for _ in range(test_scenes):
        scene = intention.sample_scene(rng)
        state = WorldState(positions=layout(scene, int(rng.integers(2**31))))
        est = learner.final(scene, state)
        states, _ = apply_plan(state, (est.plans or [[]])[0])
        wins.append(intention.satisfied(states[-1] if states else state))
    return {
        "success": float(np.mean(wins)),
        "signals": signals,
        "preference": est.preference,
        "select_s": select_s,
    }
