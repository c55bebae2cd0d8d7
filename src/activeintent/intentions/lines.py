"""A straight line of blocks on the table, written with the world's helpers only.

The held-out suites' rows are this line (heldout2 asks ``line_ok``): they must not depend on
the goal language (activeintent.goals), which the library's align now takes its row from
(goals.structures.Row with ``loaded``: the same row, checked block for block).
"""

from __future__ import annotations

from activeintent.intentions.placement import LINE_TOL, on_table
from activeintent.world import Relations, WorldState
from activeintent.world.scene import MIN_SPACING


class StraightLine:
    """All ``members`` in one straight line on the table, neighbours next to each other.

    ``axis`` is the coordinate along the line (0: x, a left-right row; 1: y, a front-back
    column); the other coordinate may spread by at most LINE_TOL.
    """

    def __init__(self, axis: int = 0):
        self.axis = axis

    def line_ok(self, state: WorldState, rel: Relations, members: list[str] | tuple[str, ...]) -> bool:
        if not members or not all(on_table(rel, b) for b in members):
            return False
        across = [state.pos(b)[1 - self.axis] for b in members]
        if max(across) - min(across) > LINE_TOL:
            return False
        ordered = sorted(members, key=lambda b: state.pos(b)[self.axis])
        for a, b in zip(ordered, ordered[1:], strict=False):
            if state.pos(b)[self.axis] - state.pos(a)[self.axis] < MIN_SPACING or not rel.is_next_to(a, b):
                return False
        return True
