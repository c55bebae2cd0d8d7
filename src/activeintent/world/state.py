"""World state: where each object is. Kind and colour are read from the name."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel

from activeintent.world.scene import Scene, color_of, kind_of


class WorldState(BaseModel):
    """Object centre positions in metres (bowls: centre of the base, z = 0)."""

    model_config = {"frozen": True}

    positions: dict[str, tuple[float, float, float]]

    @property
    def names(self) -> list[str]:
        return list(self.positions)

    @property
    def blocks(self) -> list[str]:
        return [n for n in self.positions if kind_of(n) == "block"]

    @property
    def bowls(self) -> list[str]:
        return [n for n in self.positions if kind_of(n) == "bowl"]

    @property
    def scene(self) -> Scene:
        return Scene(objects=list(self.positions))

    def pos(self, name: str) -> np.ndarray:
        return np.asarray(self.positions[name], dtype=float)

    def moved(self, name: str, position: tuple[float, float, float]) -> WorldState:
        new = dict(self.positions)
        new[name] = tuple(float(v) for v in position)  # type: ignore[assignment]
        return WorldState.model_construct(positions=new)  # valid already: skip re-checking every position

    @staticmethod
    def color(name: str) -> str:
        return color_of(name)

    @staticmethod
    def kind(name: str) -> str:
        return kind_of(name)
