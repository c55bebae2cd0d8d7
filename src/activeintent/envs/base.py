"""The Env protocol: ``reset(scene, seed) -> state``, ``execute(plan) -> τ``, ``close()``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol, runtime_checkable

from activeintent.envs.symbolic import SymbolicEnv
from activeintent.registry import Registry
from activeintent.world import Scene, Skill, WorldState
from activeintent.world.trajectory import Trajectory


@runtime_checkable
class Env(Protocol):
    name: str
    renders: bool  # can its trajectories be drawn (frames for MLLMs, videos for people)?
    physical: bool  # does it simulate physics (then final answers are also scored in it)?

    def reset(self, scene: Scene, seed: int) -> WorldState:
        """Lay ``scene`` out from ``seed``; returns the initial state."""

    def execute(self, plan: Sequence[Skill]) -> Trajectory:
        """Run ``plan`` from the current state; returns its log τ."""

    def close(self) -> None: ...


ENVS: Registry[Env] = Registry("env")


@ENVS.register("symbolic", help="the symbolic world model: fast, no physics, no images")
def _symbolic() -> Env:
    return SymbolicEnv()


@ENVS.register("pybullet", help="PyBullet physics with a Panda arm; renders frames")
def _pybullet() -> Env:
    # lazy: PyBullet loads (and prints its banner) only when this env is chosen
    from activeintent.sim.env import PyBulletEnv

    return PyBulletEnv()


def make_env(name: str) -> Env:
    return ENVS.make(name)
