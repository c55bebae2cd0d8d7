"""τ: the per-tick log of an execution, pure data shared by every env, user and learner.

Frames are not part of τ: an env that can draw (PyBullet) attaches a ``renderer`` so that
learners needing images (I_0, I_b, I_s) ask ``traj.frame(t)`` without importing ``sim/``.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydantic import TypeAdapter

from activeintent.world.scene import Scene
from activeintent.world.skills import Skill
from activeintent.world.state import WorldState

_SKILL = TypeAdapter(Skill)


class RenderUnavailable(RuntimeError):
    """Asked for a frame of τ that no renderer can draw."""


@dataclass
class StepRecord:
    """One executed skill: its tick range, the tick at which its destination becomes evident
    (the block is lifted and starts moving), success, and the states around it."""

    index: int
    skill: Skill
    start_tick: int
    reveal_tick: int
    end_tick: int
    ok: bool
    reason: str | None
    state_before: WorldState
    state_after: WorldState

    def to_json(self) -> dict:
        return {
            "index": self.index,
            "skill": self.skill.model_dump(),
            "start_tick": self.start_tick,
            "reveal_tick": self.reveal_tick,
            "end_tick": self.end_tick,
            "ok": self.ok,
            "reason": self.reason,
            "state_before": self.state_before.model_dump(),
            "state_after": self.state_after.model_dump(),
        }

    @classmethod
    def from_json(cls, d: dict) -> StepRecord:
        return cls(
            index=d["index"],
            skill=_SKILL.validate_python(d["skill"]),
            start_tick=d["start_tick"],
            reveal_tick=d["reveal_tick"],
            end_tick=d["end_tick"],
            ok=d["ok"],
            reason=d["reason"],
            state_before=WorldState.model_validate(d["state_before"]),
            state_after=WorldState.model_validate(d["state_after"]),
        )


@dataclass
class Trajectory:
    """Log of τ = f(y) at a fixed tick interval ``dt`` (seconds of simulated time).

    Arrays have one row per tick: ``object_poses`` [T, N, 7] (xyz + quaternion xyzw, in the
    order of ``object_names``), ``joint_positions`` [T, J], ``ee_pose`` [T, 7],
    ``gripper_closed`` [T], ``step_index`` [T] (-1 while idle). ``object_poses``,
    ``joint_positions`` and ``ee_pose`` may be given as callables run when first read (an env's
    arm solved only for drawing, a predicted τ whose poses nobody looks at).
    """

    scene: Scene
    seed: int
    dt: float
    object_names: list[str]
    object_poses: np.ndarray
    joint_positions: np.ndarray
    ee_pose: np.ndarray
    gripper_closed: np.ndarray
    step_index: np.ndarray
    steps: list[StepRecord] = field(default_factory=list)
    initial_state: WorldState | None = None
    final_state: WorldState | None = None
    renderer: Callable[[Trajectory, float, tuple[int, int]], np.ndarray] | None = field(
        default=None, repr=False, compare=False
    )

    @property
    def n_ticks(self) -> int:
        return int(self.step_index.shape[0])

    @property
    def duration(self) -> float:
        return max(0.0, (self.n_ticks - 1) * self.dt)

    @property
    def times(self) -> np.ndarray:
        return np.arange(self.n_ticks) * self.dt

    @property
    def failures(self) -> list[StepRecord]:
        return [s for s in self.steps if not s.ok]

    def tick_at(self, t: float) -> int:
        """Log index at time t (clipped to the trajectory)."""
        return int(np.clip(round(t / self.dt), 0, max(0, self.n_ticks - 1)))

    def time_of(self, tick: int) -> float:
        return tick * self.dt

    def step_at(self, t: float) -> int | None:
        """Index of the skill being executed at time t (the last one started, if idle)."""
        tick = self.tick_at(t)
        idx = int(self.step_index[tick])
        if idx >= 0:
            return idx
        started = [s.index for s in self.steps if s.start_tick <= tick]
        return started[-1] if started else None

    def state_at(self, t: float) -> WorldState:
        tick = self.tick_at(t)
        return WorldState(
            positions={
                n: tuple(float(v) for v in self.object_poses[tick, i, :3])
                for i, n in enumerate(self.object_names)
            }
        )

    @property
    def outcome(self) -> WorldState:
        """The state τ ends in: the logged final state, else the last tick, else the start."""
        if self.final_state is not None:
            return self.final_state
        if self.steps:
            return self.steps[-1].state_after
        if self.n_ticks > 0:
            return self.state_at(self.duration)
        if self.initial_state is not None:
            return self.initial_state
        raise ValueError("the trajectory has no states (no ticks, no initial or final state)")

    @property
    def moved_anything(self) -> bool:
        """False for an empty or wholly failed execution: nothing was shown to the user."""
        return any(s.ok for s in self.steps)

    def frame(self, t: float, size: tuple[int, int] = (240, 240)) -> np.ndarray:
        """RGB image (H, W, 3) uint8 of the scene at time t, drawn by the env's renderer."""
        if self.renderer is None:
            raise RenderUnavailable(
                "this trajectory comes from an env that cannot draw (e.g. --env symbolic); "
                "use --env pybullet for learners that need images"
            )
        return self.renderer(self, t, size)

    def save(self, path: str | Path) -> Path:
        """Write ``path`` (.npz): arrays plus a JSON header; readable by :meth:`load`."""
        path = Path(path)
        header = {
            "scene": list(self.scene.objects),
            "seed": self.seed,
            "dt": self.dt,
            "object_names": self.object_names,
            "steps": [s.to_json() for s in self.steps],
            "initial_state": self.initial_state.model_dump() if self.initial_state else None,
            "final_state": self.final_state.model_dump() if self.final_state else None,
        }
        np.savez_compressed(
            path,
            header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8),
            object_poses=self.object_poses,
            joint_positions=self.joint_positions,
            ee_pose=self.ee_pose,
            gripper_closed=self.gripper_closed,
            step_index=self.step_index,
        )
        return path

    @classmethod
    def load(cls, path: str | Path) -> Trajectory:
        with np.load(path) as data:
            header = json.loads(bytes(data["header"]).decode())
            arrays = {k: data[k] for k in ("object_poses", "joint_positions", "ee_pose", "gripper_closed", "step_index")}
        return cls(
            scene=Scene(objects=header["scene"]),
            seed=header["seed"],
            dt=header["dt"],
            object_names=header["object_names"],
            steps=[StepRecord.from_json(s) for s in header["steps"]],
            initial_state=WorldState.model_validate(header["initial_state"]) if header["initial_state"] else None,
            final_state=WorldState.model_validate(header["final_state"]) if header["final_state"] else None,
            **arrays,
        )


def _deferred(name: str) -> property:
    """An array field of τ that may be given as a callable, run on first read: it returns the
    array, or a dict of arrays for this and other deferred fields (computed together)."""

    def get(self: Trajectory) -> np.ndarray:
        value = self.__dict__[name]
        if callable(value):
            made = value()
            if isinstance(made, dict):
                self.__dict__.update(made)
            else:
                self.__dict__[name] = made
            value = self.__dict__[name]
        return value

    def set(self: Trajectory, value: np.ndarray | Callable[[], np.ndarray | dict[str, np.ndarray]]) -> None:
        self.__dict__[name] = value

    return property(get, set)


for _name in ("object_poses", "joint_positions", "ee_pose"):
    setattr(Trajectory, _name, _deferred(_name))
