"""Adding a relation to the goal language of ``lang-*``: one class, one ``register`` call.

A relation says something about one block in a state; the language then combines it with
every quantifier and selector ("every warm-coloured block is far from the red bowl", "no block
is …"), the planner uses its ``targets`` as first suggestions (and its own generic moves
otherwise), and the space is rebuilt because the registry is part of the cache key.

Try it:

    python examples/my_relation.py
"""

from __future__ import annotations

import numpy as np

from activeintent.goals.facts import facts
from activeintent.goals.language import Each, Goal, Relation, register
from activeintent.goals.planner import plan, run
from activeintent.goals.relations import region_points
from activeintent.world import PutAt, Scene, WorldState, layout
from activeintent.world.colors import COLOR_NAMES


class FarFromBowl(Relation):
    """The block rests on the table at least 25 cm from the named bowl."""

    key = "far-from"
    params = COLOR_NAMES  # one choice per bowl colour: log2(10) bits for the parameter

    def phrase(self, p):
        return f"at least 25 cm away from the {p} bowl"

    def refers(self, p):
        return f"{p} bowl"  # must be in the scene

    def ok(self, f, b, p):
        (x, y), (bx, by) = f.xy[b], f.xy[f"{p} bowl"]
        return f.bowl_of[b] is None and np.hypot(x - bx, y - by) >= 0.25

    def targets(self, state, b, p):
        # suggest the corners; the planner checks each move on the world model
        corners = ("back left corner", "back right corner", "front left corner", "front right corner")
        return [PutAt(block=b, position=region_points(c)[0]) for c in corners]


register(FarFromBowl())

if __name__ == "__main__":
    goal = Goal((Each("every", "all", "", "far-from", "blue"),))
    scene = Scene(objects=["red block", "green block", "blue bowl"])
    state = WorldState(positions=layout(scene, 3))
    steps = plan(goal, state)
    print(goal.sentence(), f"({goal.bits:.2f} bits)")
    print("plan:", steps)
    print("satisfied:", steps is not None and goal.holds(facts(run(state, steps))))
