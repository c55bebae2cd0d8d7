"""Scene designs that ask again on tables the person has answered about.

    bin/activeintent bench --plugin experiments/answered-scenes/answered.py --scenes answered ...

A "new scene" answer says the person cannot show their intention on that table; an answer about
the trajectories says they can. The belief's own guess of which tables can show z (``belief``)
is only as good as the belief, so these designs lean on what the person's answers showed:

``answered``: once some table got an answer about its trajectories, the candidates are those
tables' objects laid out anew (the most recent first, ``n_scenes`` at most; a table whose latest
answer was "new scene" is left out); before that, the ``belief`` design's candidates. EIG
chooses among them as usual.
"""

from __future__ import annotations

from collections.abc import Iterator

from activeintent.learners.bayes.scenes import SCENE_DESIGNS, Design, belief_scenes, sampled_scenes
from activeintent.world import Scene


def answered_tables(learner) -> list[tuple[str, ...]]:
    """The object sets of the tables whose latest answer was about the trajectories (not "new
    scene": a person may miss that a table cannot show their intention once, and say so later),
    most recent first."""
    latest: dict[tuple[str, ...], bool] = {}
    for o in reversed(learner.observations):
        latest.setdefault(tuple(o.scene.objects), not o.answer.new_scene)
    return [objects for objects, answered in latest.items() if answered]


def answered_scenes(learner) -> Iterator[Scene]:
    if learner.config.choose == "random":
        yield from sampled_scenes(learner)
        return
    tables = answered_tables(learner)[:learner.config.n_scenes]
    if not tables:
        yield from belief_scenes(learner)
        return
    for objects in tables:
        yield Scene(objects=list(objects))


SCENE_DESIGNS.register("answered", Design(answered_scenes, True, "tables already answered about, laid out anew"),
                       help="tables the person answered about, laid out anew (belief's before any answer)")
