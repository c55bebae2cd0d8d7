"""The Franka Panda from pybullet_data: inverse kinematics and a suction-style grasp.

The arm is driven kinematically (joint positions are set every physics tick along IK
waypoints), which is fast and exactly repeatable; its links do not collide with anything.
The objects are fully simulated: a grasped block hangs on a fixed constraint that follows
the hand, and is dropped into real contact with the table, bowls and other blocks.
"""

from __future__ import annotations

import numpy as np
import pybullet as p
import pybullet_data

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
    """A kinematically driven Panda in one PyBullet client."""

    def __init__(self, client: int):
        self.client = client
        p.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=client)
        self.body = p.loadURDF(
            PANDA_URDF, BASE_POSITION, p.getQuaternionFromEuler([0, 0, BASE_YAW]),
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
        self._grasp_offset: tuple[tuple[float, ...], tuple[float, ...]] | None = None
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

    def solve(
        self, target: tuple[float, float, float] | np.ndarray, seeds: list | None = None,
        fingers: float = FINGER_OPEN,
    ) -> tuple[np.ndarray, float]:
        """Joint positions putting the grasp point at ``target`` pointing down, and the
        remaining position error (m). Starts from the current joints (continuity), then from
        ``seeds``; the joint state is left unchanged."""
        target = np.asarray(target, dtype=float)
        saved = self.joints()
        # Fast path while tracking a path: one damped-least-squares solve from the current
        # joints is exact when the target is close to where the hand already is.
        q = np.array(p.calculateInverseKinematics(
            self.body, EE_LINK, target, DOWN, maxNumIterations=50, residualThreshold=1e-6,
            physicsClientId=self.client,
        ))
        q[-2:] = fingers
        if np.all(q >= self.lower) and np.all(q <= self.upper):
            err = self._fk_error(q, target)
            if err < 5e-4:
                self.set_joints(saved)
                return q, err
        starts = [saved] + [np.array([*s, fingers, fingers]) for s in (seeds or [])]
        best, best_err = saved, np.inf
        for start in starts:
            q = np.array(start, dtype=float)
            # One pass pulled towards the start (keeps the arm's configuration), then plain
            # damped least squares to remove the residual that the null-space pull leaves.
            # (IK starts from the body's joint state: passing currentPositions ignores the
            # base pose in PyBullet 3.2, so the joints are set instead.)
            self.set_joints(q)
            q = np.array(p.calculateInverseKinematics(
                self.body, EE_LINK, target, DOWN, self.lower, self.upper, self.ranges, list(q),
                maxNumIterations=50, residualThreshold=1e-5, physicsClientId=self.client,
            ))
            for _ in range(2):
                self.set_joints(q)
                q = np.array(p.calculateInverseKinematics(
                    self.body, EE_LINK, target, DOWN, maxNumIterations=50,
                    residualThreshold=1e-6, physicsClientId=self.client,
                ))
            q = np.clip(q, self.lower, self.upper)
            q[-2:] = fingers
            err = self._fk_error(q, target)
            if err < best_err:
                best, best_err = q, err
            if best_err < 5e-4:
                break
        self.set_joints(saved)
        return best, best_err

    # --- suction-style grasp ------------------------------------------------------------
    def grasp(self, body: int) -> None:
        """Hold ``body`` rigidly at its current pose relative to the hand."""
        pos, orn = self.ee_pose()
        bpos, born = p.getBasePositionAndOrientation(body, physicsClientId=self.client)
        inv = p.invertTransform(pos, orn)
        self._grasp_offset = p.multiplyTransforms(*inv, bpos, born)
        self._grasp = p.createConstraint(
            body, -1, -1, -1, p.JOINT_FIXED, (0, 0, 0), (0, 0, 0), bpos,
            childFrameOrientation=born, physicsClientId=self.client,
        )
        p.changeConstraint(self._grasp, maxForce=200.0, physicsClientId=self.client)
        self.grasped = body

    def grasp_offset_world(self) -> np.ndarray:
        """Where the held body's centre is relative to the grasp point, in world axes."""
        assert self._grasp_offset is not None
        return np.array(p.multiplyTransforms((0, 0, 0), DOWN, self._grasp_offset[0], (0, 0, 0, 1))[0])

    def follow(self) -> None:
        """Move the grasp constraint's anchor to the hand (call after each joint update)."""
        if self._grasp is None or self._grasp_offset is None:
            return
        pos, orn = self.ee_pose()
        tpos, torn = p.multiplyTransforms(pos, orn, *self._grasp_offset)
        p.changeConstraint(
            self._grasp, jointChildPivot=tpos, jointChildFrameOrientation=torn, maxForce=200.0,
            physicsClientId=self.client,
        )

    def release(self) -> None:
        if self._grasp is not None:
            p.removeConstraint(self._grasp, physicsClientId=self.client)
        self._grasp = self._grasp_offset = self.grasped = None
