"""The Franka Panda from pybullet_data: inverse kinematics and a suction-style grasp.

The arm is kinematic: its links touch nothing, and its joints are solved by IK along the
commanded grasp points only when a trajectory is drawn (:class:`ArmReplay`). The objects are
fully simulated: a grasped block hangs on a fixed constraint that follows the commanded grasp
point, and is dropped into real contact with the table, bowls and other blocks.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
import pybullet as p
import pybullet_data

from activeintent.sim.assets import light_panda_urdf

PANDA_URDF = "franka_panda/panda.urdf"
# Behind the middle of the top side of the workspace: every point of BOUNDS (plus the reach
# margin) is reachable with the gripper pointing straight down (checked by tests/sim).
BASE_POSITION = (0.0, -0.1, 0.0)
BASE_YAW = -np.pi / 2  # facing the workspace (-y)
ARM_JOINTS = (0, 1, 2, 3, 4, 5, 6)
FINGER_JOINTS = (9, 10)
EE_LINK = 11  # panda_grasptarget: between the fingertips
FINGER_OPEN = 0.04
FINGER_CLOSED = 0.02  # a 4 cm block between the fingers
# A comfortable elbow-up configuration; the home pose and the IK restarts start here.
REST_POSE = (0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785)
SEED_POSES = (REST_POSE, (0.0, 0.3, 0.0, -2.8, 0.0, 3.0, 0.785), (0.0, 0.6, 0.0, -1.5, 0.0, 2.1, 0.785))
DOWN = p.getQuaternionFromEuler([np.pi, 0.0, BASE_YAW])  # gripper pointing at the table
HOME_EE = (0.0, -0.28, 0.42)


class Panda:
    """A kinematically driven Panda."""

    def __init__(self, client: int, world: int | None = None):
        """The arm lives in ``client`` (kinematics only); held objects live in ``world``
        (the physics client; the same one if not given). Keeping the arm out of the physics
        world makes each physics step cheaper: it never touches anything anyway."""
        self.client = client
        self.world = client if world is None else world
        p.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=client)
        self.body = p.loadURDF(
            light_panda_urdf(), BASE_POSITION, p.getQuaternionFromEuler([0, 0, BASE_YAW]),
            useFixedBase=True, physicsClientId=client,
        )
        n = p.getNumJoints(self.body, physicsClientId=client)
        for link in range(-1, n):  # the arm moves through the scene without touching it
            p.setCollisionFilterGroupMask(self.body, link, 0, 0, physicsClientId=client)
        self.movable = [
            j for j in range(n)
            if p.getJointInfo(self.body, j, physicsClientId=client)[2] != p.JOINT_FIXED
        ]
        info = [p.getJointInfo(self.body, j, physicsClientId=client) for j in self.movable]
        self.lower = [i[8] for i in info]
        self.upper = [i[9] for i in info]
        self.ranges = [u - lo for lo, u in zip(self.lower, self.upper, strict=True)]
        self._grasp: int | None = None
        self._offset: np.ndarray | None = None
        self._held_orn: tuple[float, ...] = (0.0, 0.0, 0.0, 1.0)
        self.grasped: int | None = None
        self.home = self.solve(HOME_EE, seeds=[REST_POSE])[0]
        self.set_joints(self.home)

    # --- kinematics -------------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return len(self.movable)

    def joints(self) -> np.ndarray:
        """Positions of all movable joints (7 arm + 2 fingers)."""
        states = p.getJointStates(self.body, self.movable, physicsClientId=self.client)
        return np.array([s[0] for s in states])

    def set_joints(self, q: np.ndarray | list[float]) -> None:
        p.resetJointStatesMultiDof(
            self.body, self.movable, [[float(v)] for v in q], physicsClientId=self.client
        )

    def ee_pose(self) -> tuple[np.ndarray, np.ndarray]:
        ls = p.getLinkState(self.body, EE_LINK, computeForwardKinematics=True, physicsClientId=self.client)
        return np.array(ls[4]), np.array(ls[5])

    def _fk_error(self, q: np.ndarray, target: np.ndarray) -> float:
        self.set_joints(q)
        return float(np.linalg.norm(self.ee_pose()[0] - target))

    def _ik(self, target: np.ndarray, start: np.ndarray, orient: bool, null_space: bool) -> np.ndarray:
        """One PyBullet IK call from ``start`` (it reads the body's joints; passing
        currentPositions would ignore the rotated base pose in PyBullet 3.2)."""
        self.set_joints(start)
        kwargs: dict = {
            "maxNumIterations": 50, "residualThreshold": 1e-5,
            "physicsClientId": self.client,
        }
        if null_space:
            kwargs.update(lowerLimits=self.lower, upperLimits=self.upper, jointRanges=self.ranges,
                          restPoses=list(start))
        args = (self.body, EE_LINK, target) + ((DOWN,) if orient else ())
        return np.array(p.calculateInverseKinematics(*args, **kwargs))

    def solve(
        self, target: tuple[float, float, float] | np.ndarray, seeds: list | None = None,
        fingers: float = FINGER_OPEN,
    ) -> tuple[np.ndarray, float]:
        """Joint positions putting the grasp point at ``target`` and the remaining position
        error (m); the joint state is left unchanged.

        The gripper points straight down where it can. Close in front of the base the Panda
        cannot do that, so the hand may tilt there (the grasp is suction-like: a held block
        keeps its own orientation). Tries the current joints first (continuity while
        tracking a path), then ``seeds``.
        """
        target = np.asarray(target, dtype=float)
        saved = self.joints()
        starts = [saved] + [np.array([*s, fingers, fingers]) for s in (seeds or [])]
        best, best_err = saved, np.inf
        for orient in (True, False):
            for i, start in enumerate(starts):
                if i == 0:  # tracking: plain damped least squares from where the arm is
                    q = self._ik(target, start, orient, null_space=False)
                else:  # restart: keep the seed's configuration, then remove the residual
                    q = self._ik(target, start, orient, null_space=True)
                    q = self._ik(target, q, orient, null_space=False)
                q[-2:] = fingers
                if np.any(q < np.array(self.lower) - 1e-6) or np.any(q > np.array(self.upper) + 1e-6):
                    q = np.clip(q, self.lower, self.upper)
                err = self._fk_error(q, target)
                if orient:
                    tilt = 1.0 - abs(float(np.dot(self.ee_pose()[1], DOWN)))
                    err += tilt  # a wrong orientation must not pass as a solution
                if err < best_err:
                    best, best_err = q, err
                if best_err < 5e-4:
                    self.set_joints(saved)
                    return best, best_err
        self.set_joints(saved)
        return best, best_err

    # --- suction-style grasp ------------------------------------------------------------
    def grasp(self, body: int, at: np.ndarray | None = None) -> None:
        """Hold ``body`` at its current offset from the grasp point ``at`` (default: where the
        hand is); it keeps its orientation."""
        pos = self.ee_pose()[0] if at is None else np.asarray(at, dtype=float)
        bpos, born = p.getBasePositionAndOrientation(body, physicsClientId=self.world)
        self._offset = np.array(bpos) - pos
        self._held_orn = born
        self._grasp = p.createConstraint(
            body, -1, -1, -1, p.JOINT_FIXED, (0, 0, 0), (0, 0, 0), bpos,
            childFrameOrientation=born, physicsClientId=self.world,
        )
        p.changeConstraint(self._grasp, maxForce=200.0, physicsClientId=self.world)
        self.grasped = body

    def grasp_offset_world(self) -> np.ndarray:
        """Where the held body's centre is relative to the grasp point (world axes)."""
        assert self._offset is not None
        return self._offset.copy()

    def follow(self, pos: np.ndarray | None = None) -> None:
        """Move the grasp constraint's anchor with the hand (grasp point ``pos``, default:
        where the hand is now)."""
        if self._grasp is None or self._offset is None:
            return
        if pos is None:
            pos, _ = self.ee_pose()
        p.changeConstraint(
            self._grasp, jointChildPivot=(pos + self._offset).tolist(),
            jointChildFrameOrientation=self._held_orn, maxForce=200.0, physicsClientId=self.world,
        )

    def reset(self) -> None:
        """Back to the home pose, holding nothing (the world may have been rebuilt)."""
        self._grasp = self._offset = self.grasped = None
        self.set_joints(self.home)

    def release(self) -> None:
        if self._grasp is not None:
            p.removeConstraint(self._grasp, physicsClientId=self.world)
        self._grasp = self._offset = self.grasped = None


# --- the drawn arm ------------------------------------------------------------------------
_REPLAY_ARM: Panda | None = None
_REPLAY_LOCK = threading.Lock()


def _replay_arm() -> Panda:
    """This process's kinematic Panda for :class:`ArmReplay` (its own DIRECT client)."""
    global _REPLAY_ARM
    if _REPLAY_ARM is None:
        _REPLAY_ARM = Panda(p.connect(p.DIRECT))
    return _REPLAY_ARM


@dataclass(frozen=True, eq=False)
class ArmReplay:
    """The arm's joints [T, 9] and hand pose [T, 7] along τ, solved by IK from the commanded
    grasp points when first asked for (only drawing needs them: the physics moves a held block
    along the commanded points, so an episode without video never solves IK per tick).

    Tick 0 starts from the home pose; each later tick tracks from the one before (restarting
    from SEED_POSES when tracking loses the point), as the hand moved."""

    points: np.ndarray  # [T, 3] commanded grasp point per tick
    fingers: np.ndarray  # [T] finger opening per tick
    tolerance: float  # largest IK error before restarting from the seed poses

    def __call__(self) -> dict[str, np.ndarray]:
        with _REPLAY_LOCK:
            arm = _replay_arm()
            saved = arm.joints()
            joints = np.zeros((len(self.points), arm.n_joints))
            ee = np.zeros((len(self.points), 7))
            q = np.array(arm.home, dtype=float)
            for t, (point, fingers) in enumerate(zip(self.points, self.fingers, strict=True)):
                if t > 0 and np.array_equal(point, self.points[t - 1]):  # the hand holds still
                    q = q.copy()
                    q[-2:] = fingers
                else:
                    arm.set_joints(q)
                    q, err = arm.solve(point, fingers=fingers)
                    if err > self.tolerance:
                        q, _ = arm.solve(point, seeds=list(SEED_POSES), fingers=fingers)
                arm.set_joints(q)
                pos, orn = arm.ee_pose()
                joints[t], ee[t] = q, np.concatenate([pos, orn])
            arm.set_joints(saved)
        return {"joint_positions": joints, "ee_pose": ee}
