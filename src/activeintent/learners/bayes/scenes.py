"""Scene designs: which candidate scenes a Bayesian learner scores in ``design_scene``.

A design is chosen by name (``--scenes``): ``sampled`` draws random scenes, ``belief`` draws
scenes that the belief expects to be able to show its likely z (a scene that cannot show z
costs an answer, "new scene", that tells little). Register your own in ``SCENE_DESIGNS``
(``SCENE_DESIGNS.register("name", Design(...))`` in a ``--plugin`` file).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from activeintent import ranking
from activeintent.learners.bayes.acquisition import particles
from activeintent.learners.bayes.hypotheses import random_scene
from activeintent.registry import Registry
from activeintent.world import Scene


class BeliefView(Protocol):
    """What a design reads of the learner that calls it (the learner calls the design, not the
    other way round): its settings, its random stream and its belief."""

    config: Any  # n_scenes, scene_candidates, choose
    rng: np.random.Generator
    hyps: Sequence[Any]

    @property
    def weights(self) -> np.ndarray: ...


@dataclass(frozen=True)
class Design:
    """``candidates(learner)`` yields the scenes to score (drawn from the learner's own rng);
    ``after_new_scene``: the learner designs the next scene after a "new scene" answer too
    (otherwise the protocol samples it)."""

    candidates: Callable[[BeliefView], Iterator[Scene]]
    after_new_scene: bool
    description: str


def sampled_scenes(learner: BeliefView) -> Iterator[Scene]:
    """``n_scenes`` random scenes (one for the random-query baseline), each followed in the
    learner's stream by its layout's draw."""
    c = learner.config
    for _ in range(1 if c.choose == "random" else c.n_scenes):
        yield random_scene(learner.rng)


def belief_scenes(learner: BeliefView) -> Iterator[Scene]:
    """Each of ``scene_candidates`` candidates is a random scene that can show a z drawn from the
    belief (up to 20 draws); kept are the ``n_scenes`` that can show the most of the likely z
    (those holding 99 % of the belief, at most 64)."""
    c = learner.config
    if c.choose == "random":  # the baseline asks at random: it designs nothing either
        yield from sampled_scenes(learner)
        return
    hyps, rng = learner.hyps, learner.rng
    likely = particles(learner.weights, mass=0.99, cap=64)
    w = learner.weights[likely] / learner.weights[likely].sum()
    drawn = []
    for _ in range(c.scene_candidates):
        z = hyps[likely[int(rng.choice(len(likely), p=w))]]
        for _ in range(20):
            scene = random_scene(rng)
            if z.can_show(tuple(scene.objects)):
                break
        drawn.append(scene)
    mass = np.array([sum(w[j] for j, i in enumerate(likely) if hyps[i].can_show(tuple(s.objects))) for s in drawn])
    keep = ranking.order(mass)[:c.n_scenes]  # most likely to be shown; ties to the first drawn
    yield from (drawn[i] for i in sorted(keep))


SCENE_DESIGNS: Registry[Design] = Registry("scene design")
SCENE_DESIGNS.register("sampled", Design(sampled_scenes, False, "random scenes; the protocol samples after 'new scene'"),
                       help="random scenes")
SCENE_DESIGNS.register("belief", Design(belief_scenes, True, "scenes the belief expects to show its likely z, also after 'new scene'"),
                       help="scenes the belief expects to show its likely z")
