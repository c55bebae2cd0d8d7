"""What a hidden user intention is: a named, described predicate over world states."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from activeintent.world import Scene, Skill, WorldState


class Intention(ABC):
    """A user intention.

    Subclasses set ``name`` (command-line name, e.g. ``color-match``) and ``description``
    (one sentence, as a user would say it), and implement the abstract methods.
    """

    name: str = ""
    description: str = ""

    @abstractmethod
    def satisfied(self, state: WorldState) -> bool:
        """Does the state realise the intention?"""

    @abstractmethod
    def score(self, state: WorldState) -> float:
        """Graded agreement in [0, 1]: fraction of blocks placed as the intention wants."""

    @abstractmethod
    def feasible(self, scene: Scene) -> bool:
        """Can the intention be shown (and satisfied) in this scene?"""

    @abstractmethod
    def sample_scene(self, rng: np.random.Generator) -> Scene:
        """A random scene of 3–5 objects in which the intention is feasible."""

    @abstractmethod
    def plan(self, state: WorldState) -> list[Skill] | None:
        """A plan that satisfies the intention from ``state`` (None when impossible)."""

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        """Did executing ``step`` (before → after) move away from the intention?

        Default: the moved block now sits where the intention does not want it, judged by a
        drop in score or by the moved block being misplaced when it was not before.
        """
        return self.score(after) < self.score(before) - 1e-9

    def __repr__(self) -> str:
        return f"<Intention {self.name}: {self.description}>"
