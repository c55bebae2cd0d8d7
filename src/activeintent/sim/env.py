"""The PyBullet tabletop: build a scene from a seed, execute a plan, get τ back.

>>> env = TabletopEnv(SimConfig())
>>> state = env.reset(["red block", "blue bowl", "green block"], seed=0)
>>> traj = env.execute([PutIn(block="red block", bowl="blue bowl")])

Each skill is one pick-and-place along straight grasp-point segments (hover, descend, grasp,
lift, move, lower, release, retreat); the arm's joints are solved along them when drawn. Where
the block goes comes from the symbolic world model
(:func:`activeintent.world.predict.target_position`), so the simulated final state matches
:func:`~activeintent.world.predict.apply_plan` up to settling. A skill that cannot be done is
recorded as a failed step with its reason and a short pause; it never raises.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pybullet as p
from pydantic import BaseModel, Field, TypeAdapter, ValidationError, model_validator

from activeintent.sim.assets import create_object, create_table
from activeintent.sim.render import render_frame
from activeintent.sim.robot import FINGER_CLOSED, FINGER_OPEN, HOME_EE, SEED_POSES, ArmReplay, Panda
from activeintent.world.predict import SkillFailure, target_position
from activeintent.world.scene import BLOCK_SIZE, BOWL_HEIGHT, Scene, SceneError, kind_of, layout
from activeintent.world.skills import Skill
from activeintent.world.state import WorldState
from activeintent.world.trajectory import StepRecord, Trajectory

_SKILL = TypeAdapter(Skill)


class SimConfig(BaseModel):
    """Simulation and motion settings. Speeds are in m/s, durations in seconds."""

    physics_hz: int = Field(240, ge=60, description="physics steps per simulated second")
    log_hz: int = Field(60, ge=1, description="rows of the trajectory log per second (1/dt)")
    travel_speed: float = Field(0.5, gt=0, description="hand speed when moving over the table")
    vertical_speed: float = Field(0.3, gt=0, description="hand speed when descending or lifting")
    min_segment_s: float = Field(0.25, ge=0, description="shortest duration of one motion segment")
    grasp_s: float = Field(0.15, ge=0, description="pause while the gripper closes")
    release_s: float = Field(0.15, ge=0, description="pause while the gripper opens")
    clearance: float = Field(0.05, gt=0, description="gap between a carried block and the tallest object")
    min_travel_height: float = Field(0.16, gt=0, description="lowest height of the hand while travelling")
    grasp_height: float = Field(0.005, description="grasp point above the block's centre")
    drop_height: float = Field(0.004, ge=0, description="gap under a block when it is let go")
    initial_settle_s: float = Field(0.1, ge=0, description="physics run after placing a scene")
    failure_pause_s: float = Field(0.3, ge=0, description="idle time logged for a failed step")
    home_at_end: bool = Field(True, description="return to the home pose after a plan (clear last frame)")
    place_tolerance: float = Field(0.02, gt=0, description="a block ending farther from its target fails")
    solver_iterations: int = Field(30, ge=5, description="constraint solver iterations per physics step")
    ik_tolerance: float = Field(0.005, gt=0, description="largest IK error at a pick or place pose")

    @model_validator(mode="after")
    def _rates(self) -> SimConfig:
        if self.physics_hz % self.log_hz:
            raise ValueError(f"log_hz ({self.log_hz}) must divide physics_hz ({self.physics_hz})")
        return self


def _min_jerk(u: float) -> float:
    return u * u * u * (10 - 15 * u + 6 * u * u)


class _Log:
    """Rows of τ, appended once per log tick."""

    def __init__(self) -> None:
        self.poses: list[np.ndarray] = []
        self.points: list[np.ndarray] = []  # commanded grasp point (the arm is solved from it when drawn)
        self.fingers: list[float] = []
        self.closed: list[bool] = []
        self.step: list[int] = []

    @property
    def last(self) -> int:
        return len(self.step) - 1


class PyBulletEnv:
    """The ``pybullet`` env: a headless PyBullet tabletop with a Panda arm (own DIRECT client).

    Implements :class:`activeintent.envs.Env`; its trajectories carry a renderer, so frames
    (I_0, I_b, I_s, videos) can be drawn from them later.
    """

    name = "pybullet"
    renders = True
    physical = True

    def __init__(self, config: SimConfig | None = None):
        self.config = config or SimConfig()
        self.client = p.connect(p.DIRECT)  # physics: table, bowls, blocks
        self._arm_client = p.connect(p.DIRECT)  # the kinematic arm (IK / FK), kept across resets
        self._arm = Panda(self._arm_client, world=self.client)
        self.robot: Panda | None = None
        self.scene: Scene | None = None
        self.seed: int | None = None
        self.bodies: dict[str, int] = {}
        self._substeps = self.config.physics_hz // self.config.log_hz
        self._log: _Log | None = None
        self._current = -1  # index of the skill being executed (-1: idle)
        self._hand = np.zeros(3)  # the commanded grasp point (what a held block follows)
        self._finger = FINGER_OPEN  # the commanded finger opening

    # --- lifecycle ------------------------------------------------------------------------
    def __enter__(self) -> PyBulletEnv:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        if self.client >= 0:
            p.disconnect(physicsClientId=self.client)
            p.disconnect(physicsClientId=self._arm_client)
            self.client = -1

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # interpreter shutting down
            pass

    def reset(self, scene: Scene | Sequence[str], seed: int) -> WorldState:
        """Rebuild the world with ``scene`` laid out from ``seed``; returns the settled state."""
        if self.client < 0:
            raise RuntimeError("this PyBulletEnv is closed; create a new one")
        if not isinstance(scene, Scene):
            try:
                scene = Scene(objects=list(scene))
            except ValidationError as e:  # surface the scene's own message, not pydantic's
                raise SceneError("; ".join(err["msg"].removeprefix("Value error, ") for err in e.errors())) from None
        return self._build(scene, layout(scene, seed), seed)

    def reset_to(self, state: WorldState, seed: int = 0) -> WorldState:
        """Rebuild the world with objects at the given positions (e.g. a predicted state)."""
        if self.client < 0:
            raise RuntimeError("this PyBulletEnv is closed; create a new one")
        return self._build(state.scene, dict(state.positions), seed)

    def _build(self, scene: Scene, positions: dict[str, tuple[float, float, float]], seed: int) -> WorldState:
        c = self.client
        # A fresh world each time: PyBullet is deterministic only for identical call sequences.
        p.resetSimulation(physicsClientId=c)
        p.setPhysicsEngineParameter(
            fixedTimeStep=1.0 / self.config.physics_hz, numSolverIterations=self.config.solver_iterations,
            deterministicOverlappingPairs=1, physicsClientId=c,
        )
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        create_table(c)
        self._arm.reset()
        self.robot = self._arm
        self._hand = self._arm.ee_pose()[0]  # the home pose's
        self._finger = float(self._arm.home[-1])
        self.bodies = {name: create_object(c, name, positions[name]) for name in scene.objects}
        self.scene, self.seed = scene, seed
        for _ in range(round(self.config.initial_settle_s * self.config.physics_hz)):
            p.stepSimulation(physicsClientId=c)
        return self.state()

    # --- state --------------------------------------------------------------------------
    def _require(self) -> Panda:
        if self.robot is None or self.scene is None or self.client < 0:
            raise RuntimeError("call TabletopEnv.reset(scene, seed) before using the environment")
        return self.robot

    def state(self) -> WorldState:
        """Object centres from the physics (bowls: centre of the base)."""
        self._require()
        return WorldState(positions={
            name: tuple(
                float(v) for v in p.getBasePositionAndOrientation(body, physicsClientId=self.client)[0]
            )
            for name, body in self.bodies.items()
        })

    def _record(self) -> None:
        robot, log = self._require(), self._log
        assert log is not None
        log.poses.append(np.array([
            np.concatenate(p.getBasePositionAndOrientation(b, physicsClientId=self.client))
            for b in self.bodies.values()
        ]))
        log.points.append(self._hand.copy())
        log.fingers.append(self._finger)
        log.closed.append(robot.grasped is not None)
        log.step.append(self._current)

    # --- motion primitives ----------------------------------------------------------------
    def _advance(self, point: np.ndarray) -> None:
        """One log tick: the commanded grasp point moves to ``point`` over the physics substeps
        (a held block follows it) while the objects are simulated."""
        robot = self._require()
        start, end = self._hand, np.asarray(point, dtype=float)
        held = robot.grasped is not None
        for k in range(1, self._substeps + 1):
            if held:
                robot.follow(start + (end - start) * (k / self._substeps))
            p.stepSimulation(physicsClientId=self.client)
        self._hand = end
        self._record()

    def _move(self, target: np.ndarray, speed: float) -> None:
        """Straight line of the grasp point to ``target`` (min-jerk timing, one point per log
        tick; the arm is solved along it by IK when drawn)."""
        self._require()
        start = self._hand
        dist = float(np.linalg.norm(target - start))
        duration = max(self.config.min_segment_s, dist / speed)
        n = max(1, round(duration * self.config.log_hz))
        for k in range(1, n + 1):
            self._advance(start + (target - start) * _min_jerk(k / n))

    def _dwell(self, duration: float, fingers: float | None = None) -> None:
        """Hold the hand still (optionally moving the fingers) while the physics runs."""
        n = max(1, round(duration * self.config.log_hz))
        f0 = self._finger
        for k in range(1, n + 1):
            if fingers is not None:
                self._finger = f0 + (fingers - f0) * (k / n)
            self._advance(self._hand)

    def _travel_height(self, exclude: str | None = None) -> float:
        tops = [
            (BOWL_HEIGHT if kind_of(n) == "bowl" else pos[2] + BLOCK_SIZE / 2)
            for n, pos in self.state().positions.items() if n != exclude
        ]
        carried = BLOCK_SIZE / 2 + self.config.grasp_height  # block hanging below the grasp point
        return max(self.config.min_travel_height, max(tops, default=0.0) + carried + self.config.clearance)

    def _reachable(self, *points: np.ndarray) -> str | None:
        robot = self._require()
        for pt in points:
            _, err = robot.solve(pt, seeds=list(SEED_POSES))
            if err > self.config.ik_tolerance:
                return f"({pt[0]:.2f}, {pt[1]:.2f}) is out of the arm's reach"
        return None

    # --- skills ---------------------------------------------------------------------------
    def _pick_place(self, block: str, target: np.ndarray) -> tuple[int, str | None]:
        """Run the waypoints; returns the reveal tick and a failure reason (None if placed)."""
        robot, cfg, log = self._require(), self.config, self._log
        assert log is not None
        body = self.bodies[block]
        start = np.array(p.getBasePositionAndOrientation(body, physicsClientId=self.client)[0])
        grasp_pt = start + (0, 0, cfg.grasp_height)
        travel = self._travel_height(exclude=block)
        # Where the hand must be so that the block (held with a small offset) lands on target.
        place_pt = target + (0, 0, cfg.grasp_height + cfg.drop_height)
        if reason := self._reachable(np.array([*grasp_pt[:2], travel]), np.array([*place_pt[:2], travel])):
            self._dwell(cfg.failure_pause_s)
            return log.last, reason
        self._move(np.array([*grasp_pt[:2], travel]), cfg.travel_speed)  # hover
        self._move(grasp_pt, cfg.vertical_speed)  # descend
        robot.grasp(body, self._hand)
        self._dwell(cfg.grasp_s, FINGER_CLOSED)  # grasp
        offset = robot.grasp_offset_world()
        self._move(np.array([*grasp_pt[:2], travel]), cfg.vertical_speed)  # lift
        reveal = log.last
        hand = target - offset + (0, 0, cfg.drop_height)
        self._move(np.array([*hand[:2], travel]), cfg.travel_speed)  # move
        self._move(hand, cfg.vertical_speed)  # lower
        robot.release()
        self._dwell(cfg.release_s, FINGER_OPEN)  # release
        self._move(np.array([*hand[:2], self._travel_height()]), cfg.vertical_speed)  # retreat
        ended = np.array(p.getBasePositionAndOrientation(body, physicsClientId=self.client)[0])
        miss = float(np.linalg.norm(ended - target))
        if miss > cfg.place_tolerance:
            return reveal, f"the {block} did not stay where it was put ({100 * miss:.1f} cm away)"
        return reveal, None

    def execute(self, plan: Sequence[Skill | dict]) -> Trajectory:
        """Run ``plan`` from the current state and return its log τ (tick 0 = current state)."""
        robot = self._require()
        assert self.scene is not None and self.seed is not None
        steps = [s if isinstance(s, BaseModel) else _SKILL.validate_python(s) for s in plan]
        self._log = log = _Log()
        self._current = -1
        self._record()
        initial = self.state()
        records: list[StepRecord] = []
        for i, skill in enumerate(steps):
            self._current = i
            before = self.state()
            start = log.last
            target = target_position(before, skill)
            if isinstance(target, SkillFailure):
                self._dwell(self.config.failure_pause_s)
                reveal, reason = start, target.reason
            else:
                reveal, reason = self._pick_place(skill.block, np.array(target))
            records.append(StepRecord(
                index=i, skill=skill, start_tick=start, reveal_tick=reveal, end_tick=log.last,
                ok=reason is None, reason=reason, state_before=before, state_after=self.state(),
            ))
        self._current = -1
        if self.config.home_at_end and steps:
            self._move(np.array(HOME_EE), self.config.travel_speed)
        robot.release()  # nothing stays attached between plans
        arm = ArmReplay(np.array(log.points), np.array(log.fingers), self.config.ik_tolerance)
        traj = Trajectory(
            scene=self.scene, seed=self.seed, dt=1.0 / self.config.log_hz,
            object_names=list(self.bodies),
            object_poses=np.array(log.poses), joint_positions=arm, ee_pose=arm,
            gripper_closed=np.array(log.closed, dtype=bool),
            step_index=np.array(log.step, dtype=np.int64), steps=records,
            initial_state=initial, final_state=self.state(), renderer=_render,
        )
        self._log = None
        return traj


TabletopEnv = PyBulletEnv  # the name used before envs became plug-ins


def _render(traj: Trajectory, t: float, size: tuple[int, int]) -> np.ndarray:
    return render_frame(traj, t, size=size)
