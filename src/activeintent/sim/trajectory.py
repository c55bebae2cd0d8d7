"""τ: the per-tick log of an execution. Pure data; frames are rendered from it on demand."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydantic import TypeAdapter

from activeintent.world import Scene, Skill, WorldState

_SKILL = TypeAdapter(Skill)


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
    ``gripper_closed`` [T], ``step_index`` [T] (-1 while idle).
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

    @property
    def n_ticks(self) -> int:
        return int(self.object_poses.shape[0])

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

    def frame(self, t: float, size: tuple[int, int] = (240, 240)) -> np.ndarray:
        """RGB image (H, W, 3) uint8 of the scene at time t, rendered from the log."""
        from activeintent.sim.render import render_frame

        return render_frame(self, t, size=size)

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
