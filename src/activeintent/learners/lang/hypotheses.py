"""Goals of the language as hypotheses of the Bayesian learner, and as hidden intentions.

:class:`LangHypothesis` has the interface of ``bayes.hypotheses.Hypothesis`` (``bits``,
``description``, ``name``, ``holds_f``, ``score_f``, ``moved_off``, ``feasible``, ``plans``,
``plan``, ``prefetch``), so ``bayes.judge``, ``candidates``, ``belief``, ``acquisition`` and
``BayesLearner`` use it unchanged. All hypotheses of one :class:`LangSpace` share a
:class:`~activeintent.learners.lang.space.Compiled` judge: the first hypothesis asked about a
state judges every goal at once (numpy), the others read the memo.

Feasibility in a scene is the static check of the goal's nodes (named objects present, group
not empty, enough bowls, …) and, once the planner has been run for the goal in that scene, its
verdict: a scene in which the planner failed is infeasible from then on.
"""

from __future__ import annotations

import numpy as np

from activeintent.goals import planner
from activeintent.goals.facts import Facts, facts
from activeintent.goals.goal import Goal
from activeintent.goals.nodes import check_language, speaking, spoken
from activeintent.goals.prior import FittedPrior, goal_bits, load_prior
from activeintent.intentions.base import Intention
from activeintent.learners.bayes.hypotheses import Hypothesis, random_scene
from activeintent.learners.lang.space import Compiled, goal_space
from activeintent.memo import BoundedCache
from activeintent.world import Scene, Skill, WorldState


class LangSpace:
    """A tuple of goals, their shared vectorised judge and the planner verdicts so far."""

    def __init__(self, goals: list[Goal] | tuple[Goal, ...], variants: int = 2, prior: FittedPrior | None = None,
                 language: int | None = None):
        self.goals = tuple(goals)
        self.prior = prior  # None: the length prior (each goal's own bits)
        self.language = spoken() if language is None else language  # the version its bits are in
        self.compiled = Compiled(list(self.goals))
        self.variants = variants
        self.failed: dict[tuple[str, ...], set[int]] = {}
        self._feasible: dict[tuple[str, ...], tuple[int, np.ndarray]] = {}
        # by (goal, variants, exact positions): plans are a pure function of them, shared by episodes
        self._plans: BoundedCache[tuple, list[list[Skill]]] = BoundedCache(20000)
        with speaking(self.language):
            self.hypotheses = tuple(LangHypothesis(g, self, i) for i, g in enumerate(self.goals))

    def feasible(self, objects: tuple[str, ...]) -> np.ndarray:
        failed = self.failed.get(objects, set())
        got = self._feasible.get(objects)
        if got is None or got[0] != len(failed):
            arr = self.compiled.possible(objects).copy()
            arr[list(failed)] = False
            got = self._feasible[objects] = (len(failed), arr)
        return got[1]

    def reset(self) -> None:
        """Forget the planner's verdicts (a new episode starts from the static checks only:
        what an earlier episode in the same process planned must not change this one)."""
        self.failed.clear()
        self._feasible.clear()

    def plans(self, i: int, state: WorldState, variants: int | None = None) -> list[list[Skill]]:
        n = variants or self.variants
        key = (i, n, tuple(sorted(state.positions.items())))
        out = self._plans.get(key)  # plans are a pure function of (goal, state): shared by episodes
        if out is None:
            goal = self.goals[i]
            out = []
            seen: set[str] = set()
            for v in range(n):
                p = planner.plan(goal, state, variant=v)
                if p is None:
                    if v == 0:
                        break
                    continue
                k = repr(p)
                if k not in seen:
                    seen.add(k)
                    out.append(p)
            self._plans.put(key, out)
        if not out:  # the planner found no plan: infeasible in this scene from now on (this episode)
            self.failed.setdefault(tuple(state.scene.objects), set()).add(i)
        return out


class LangHypothesis(Hypothesis):
    """One goal of the language, as a hypothesis z (prior 2^-bits)."""

    def __init__(self, goal: Goal, space: LangSpace, index: int):  # noqa: D107 - no clauses of bayes
        self.goal = goal
        self.space = space
        self.index = index
        self.clauses = ()
        self.bits = goal_bits(goal, space.prior)
        self.name = goal.key

    @property
    def description(self) -> str:  # built when read: a space holds 10^5 goals
        return self.goal.sentence()

    def holds_f(self, f: Facts) -> bool:
        return bool(self.space.compiled.eval(f)[0][self.index])

    def score_f(self, f: Facts) -> float:
        return float(self.space.compiled.eval(f)[1][self.index])

    def moved_off(self, fb: Facts, fa: Facts, block: str) -> bool:
        return bool(self.space.compiled.moved_off(fb, fa, block)[self.index])

    def feasible(self, scene: Scene) -> bool:
        return bool(self.space.feasible(tuple(scene.objects))[self.index])

    def can_show(self, objects: tuple[str, ...]) -> bool:  # one goal's static check, not the space's
        return self.goal.possible(objects) and self.index not in self.space.failed.get(objects, ())

    def plans(self, state: WorldState, variants: int | None = None) -> list[list[Skill]]:
        return self.space.plans(self.index, state, variants)

    def plan(self, state: WorldState) -> list[Skill] | None:
        got = self.plans(state, 1)
        return got[0] if got else None


class GoalIntention(Intention):
    """A goal as a hidden user intention (tests, and ``--intention-file`` files)."""

    def __init__(self, goal: Goal, name: str | None = None):
        self.goal = goal
        self.name = name or "lang:" + goal.key.replace(" ", "_")
        self.description = goal.sentence()

    def satisfied(self, state: WorldState) -> bool:
        return self.goal.holds(facts(state))

    def score(self, state: WorldState) -> float:
        return self.goal.score(facts(state))

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if before.positions == after.positions:
            return False
        fb, fa = facts(before), facts(after)
        return self.goal.score(fa) < self.goal.score(fb) - 1e-9 or self.goal.moved_off(fb, fa, step.block)

    def feasible(self, scene: Scene) -> bool:
        return planner.feasible(self.goal, scene)

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        for _ in range(500):
            scene = random_scene(rng)
            if self.feasible(scene):
                return scene
        raise ValueError(f"no feasible scene of 3–5 objects for {self.goal.key!r}")

    def plan(self, state: WorldState) -> list[Skill] | None:
        return planner.plan(self.goal, state)


# By (seed, keep, prior's tag, language): a space is a pure function of them (and of the sources);
# its planner verdicts are reset per episode. A process uses one or two.
_SPACES: BoundedCache[tuple[int, int, str, int], LangSpace] = BoundedCache(16)


def lang_space(seed: int = 0, keep: int = 3000, prior: str = "length", language: int | None = None) -> LangSpace:
    """The de-duplicated hypothesis space of language ``language`` (default: the one in force):
    the ``keep`` most probable distinct goals under ``prior`` (length, fitted or file:PATH; built
    once per process, cached on disk)."""
    language = spoken() if language is None else check_language(language)
    fitted = load_prior(prior, language)
    key = (seed, keep, fitted.tag if fitted else "length", language)
    return _SPACES.get_or_make(key, lambda: LangSpace(goal_space(seed, keep, fitted, language), prior=fitted,
                                                      language=language))
