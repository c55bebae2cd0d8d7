"""An example user-defined intention: "put every block in the bowl furthest to the right".

Use it wherever a built-in intention is accepted:

    activeintent intentions --intention-file examples/my_intention.py:RightmostBowl
    activeintent run --method bayes-preference --intention-file examples/my_intention.py:RightmostBowl

See docs/intentions.md for what each method must do.
"""

from __future__ import annotations

import numpy as np

from activeintent.intentions.base import Intention
from activeintent.world import PutIn, Scene, Skill, WorldState, relations, sample_scene


class RightmostBowl(Intention):
    name = "rightmost-bowl"
    description = "Put every block in the bowl that is furthest to the right."

    @staticmethod
    def target(state: WorldState) -> str | None:
        # Bowls never move, so the target is fixed by the initial layout.
        return max(state.bowls, key=lambda w: state.pos(w)[0], default=None)

    def score(self, state: WorldState) -> float:
        target, rel = self.target(state), relations(state)
        if target is None or not state.blocks:
            return 0.0
        return sum(rel.in_bowl(b) == target for b in state.blocks) / len(state.blocks)

    def satisfied(self, state: WorldState) -> bool:
        return self.score(state) == 1.0

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        # Any move that does not end in the target bowl is a move the user would stop.
        return relations(after).in_bowl(step.block) != self.target(after)

    def feasible(self, scene: Scene) -> bool:
        return len(scene.blocks) >= 1 and len(scene.bowls) >= 2  # two bowls: "rightmost" matters

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        return sample_scene(rng, n_blocks=(1, 3), n_bowls=2)

    def plan(self, state: WorldState) -> list[Skill] | None:
        target = self.target(state)
        if target is None:
            return None
        rel = relations(state)
        # Top blocks first, so that nothing is under another block when it is picked up.
        todo = sorted((b for b in state.blocks if rel.in_bowl(b) != target), key=lambda b: -state.pos(b)[2])
        return [PutIn(block=b, bowl=target) for b in todo]
