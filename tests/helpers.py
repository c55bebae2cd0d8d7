"""Test helpers: a kinematic trajectory (no physics) built from the symbolic world model, and
hand-built world states for judging intentions."""

from __future__ import annotations

import numpy as np

from activeintent.world import Scene, Skill, WorldState, apply_skill, layout
from activeintent.world.trajectory import StepRecord, Trajectory

STEP_TICKS = 30  # ticks per skill; with dt = 0.1 s a skill takes 3 s
REVEAL = 10


def kinematic_trajectory(scene: Scene, seed: int, plan: list[Skill], dt: float = 0.1) -> Trajectory:
    """Each skill moves its block linearly to the predicted target over STEP_TICKS ticks."""
    state = WorldState(positions=layout(scene, seed))
    names = list(scene.objects)
    poses, step_index, steps = [], [], []

    def row(s: WorldState) -> np.ndarray:
        out = np.zeros((len(names), 7))
        out[:, 6] = 1.0
        out[:, :3] = [s.positions[n] for n in names]
        return out

    poses.append(row(state))
    step_index.append(-1)
    for i, skill in enumerate(plan):
        start = len(poses)
        after, fail = apply_skill(state, skill)
        a, b = row(state), row(after)
        for k in range(1, STEP_TICKS + 1):
            poses.append(a + (b - a) * k / STEP_TICKS)
            step_index.append(i)
        steps.append(StepRecord(index=i, skill=skill, start_tick=start, reveal_tick=start + REVEAL,
                                end_tick=len(poses) - 1, ok=fail is None, reason=fail.reason if fail else None,
                                state_before=state, state_after=after))
        state = after
    poses.append(row(state))
    step_index.append(-1)
    t = len(poses)
    return Trajectory(scene=scene, seed=seed, dt=dt, object_names=names, object_poses=np.array(poses),
                      joint_positions=np.zeros((t, 9)), ee_pose=np.zeros((t, 7)),
                      gripper_closed=np.zeros(t, dtype=bool), step_index=np.array(step_index),
                      steps=steps, initial_state=WorldState(positions=layout(scene, seed)), final_state=state)


# ---- hand-built states ----------------------------------------------------------------------

T = 0.02  # block centre resting on the table
IN = 0.026  # block centre resting on a bowl's floor
UP = 0.04  # one block higher


def S(**objects):
    """WorldState from keyword names: red_block=(x, y, z)."""
    return WorldState(positions={k.replace("_", " "): tuple(map(float, v)) for k, v in objects.items()})


BOWLS = dict(red_bowl=(-0.2, -0.3, 0), blue_bowl=(0.2, -0.3, 0))
