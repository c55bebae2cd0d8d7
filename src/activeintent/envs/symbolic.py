"""The ``symbolic`` env: τ predicted by the symbolic world model (``world.predict``).

Blocks jump to their targets at the end of each skill; every skill takes ``STEP_SECONDS`` and
reveals its destination ``REVEAL_FRACTION`` of the way in, so stop times mean the same as in
the simulator. Used for fast benchmarks (labelled ``env = symbolic`` in every result) and by
learners to predict what a query would show.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from activeintent.world import Scene, Skill, WorldState, apply_plan, layout
from activeintent.world.trajectory import StepRecord, Trajectory

STEP_SECONDS = 3.0  # simulated time per skill (the PyBullet arm takes 2.5–4 s)
REVEAL_FRACTION = 0.35  # the destination becomes evident this far into a skill
DT = 0.05


def symbolic_trajectory(scene: Scene, state: WorldState, plan: Sequence[Skill], seed: int = 0) -> Trajectory:
    """τ for ``plan`` from ``state`` on the symbolic world model (its pose arrays are made
    when first read: a learner predicting outcomes needs only the steps)."""
    plan = list(plan)
    states, fails = apply_plan(state, plan)
    names = list(state.positions)
    per = int(round(STEP_SECONDS / DT))
    n_ticks = per * len(plan) + 1
    step_index = np.full(n_ticks, -1)
    records, current = [], state
    for k, (step, after, fail) in enumerate(zip(plan, states, fails, strict=True)):
        start, end = k * per, (k + 1) * per
        step_index[start:end] = k
        records.append(StepRecord(
            index=k, skill=step, start_tick=start, reveal_tick=start + int(round(REVEAL_FRACTION * per)),
            end_tick=end, ok=fail is None, reason=None if fail is None else fail.reason,
            state_before=current, state_after=after,
        ))
        current = after
    poses = _Poses(names, [state, *states], per)
    return Trajectory(
        scene=scene, seed=seed, dt=DT, object_names=names, object_poses=poses,
        joint_positions=poses.arm, ee_pose=poses.arm,
        gripper_closed=np.zeros(n_ticks, dtype=bool), step_index=step_index, steps=records,
        initial_state=state, final_state=current,
    )


class _Poses:
    """The pose arrays of a symbolic τ: each block jumps to its next position at a step's end."""

    def __init__(self, names: list[str], states: list[WorldState], per: int):
        self.names, self.states, self.per = names, states, per
        self.n_ticks = per * (len(states) - 1) + 1

    def __call__(self) -> np.ndarray:
        poses = np.zeros((self.n_ticks, len(self.names), 7))
        poses[..., 6] = 1.0
        for k, st in enumerate(self.states):
            poses[k * self.per:, :, :3] = np.array([st.positions[n] for n in self.names])
        return poses

    def arm(self) -> dict[str, np.ndarray]:
        return {"joint_positions": np.zeros((self.n_ticks, 7)), "ee_pose": np.zeros((self.n_ticks, 7))}


class SymbolicEnv:
    """Implements :class:`activeintent.envs.Env` without physics."""

    name = "symbolic"
    renders = False
    physical = False

    def __init__(self) -> None:
        self.scene: Scene | None = None
        self.state: WorldState | None = None
        self.seed = 0

    def reset(self, scene: Scene, seed: int) -> WorldState:
        self.scene, self.seed = scene, seed
        self.state = WorldState(positions=layout(scene, seed))
        return self.state

    def reset_to(self, state: WorldState, seed: int = 0) -> WorldState:
        self.scene, self.seed, self.state = state.scene, seed, state
        return state

    def execute(self, plan: Sequence[Skill]) -> Trajectory:
        if self.state is None or self.scene is None:
            raise RuntimeError("call reset(scene, seed) before execute(plan)")
        traj = symbolic_trajectory(self.scene, self.state, plan, self.seed)
        self.state = traj.outcome
        return traj

    def close(self) -> None:
        pass
