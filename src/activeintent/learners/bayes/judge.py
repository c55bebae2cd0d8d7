"""The :class:`activeintent.signals.Judge` of the hypothesis space: every z judges at once."""

from __future__ import annotations

import itertools

import numpy as np

from activeintent.goals.facts import Facts, facts
from activeintent.learners.bayes.hypotheses import Hypothesis
from activeintent.world import WorldState
from activeintent.world.trajectory import Trajectory

_TOKENS = itertools.count()


def judge(hyps: tuple[Hypothesis, ...], f: Facts, token: object = None) -> tuple[np.ndarray, np.ndarray]:
    """(satisfied, score) of one state under every hypothesis, memoised on the facts under
    ``token`` (unique per judge: an id() could be reused by a later tuple)."""
    if token is None:
        token = tuple(h.name for h in hyps)
    key = ("judge", token)
    got = f.memo.get(key)
    if got is None:
        sat = np.fromiter((h.holds_f(f) for h in hyps), bool, len(hyps))
        score = np.fromiter((h.score_f(f) for h in hyps), float, len(hyps))
        got = f.memo[key] = (sat, score)
    return got


def utility(score: np.ndarray, sat: np.ndarray) -> np.ndarray:
    """u = (score + 1[satisfied]) / 2 ∈ [0, 1], elementwise."""
    return 0.5 * (np.clip(score, 0.0, 1.0) + sat.astype(float))


Steps = list[tuple[Facts, Facts, str, bool]]


def trajectory_steps(traj: Trajectory) -> Steps:
    """(facts before, facts after, moved block, executed ok) per step of τ."""
    return [(facts(s.state_before), facts(s.state_after), s.skill.block, s.ok) for s in traj.steps]


def first_away(hyps: tuple[Hypothesis, ...], steps: Steps, token: object = None) -> np.ndarray:
    """Per hypothesis, the index of the first step that moves away from it (-1: none).
    A failed step counts only when it made things worse (its score dropped)."""
    out = np.full(len(hyps), -1)
    for k, (fb, fa, block, ok) in enumerate(steps):
        todo = np.flatnonzero(out < 0)
        if not len(todo):
            break
        if fb is fa:
            continue
        _, sb = judge(hyps, fb, token)
        _, sa = judge(hyps, fa, token)
        drop = sa < sb - 1e-9
        for i in todo:
            if drop[i] or (ok and hyps[i].moved_off(fb, fa, block)):
                out[i] = k
    return out


class HypothesisJudge:
    """Judges outcomes under every hypothesis of H (n = |H|)."""

    def __init__(self, hyps: tuple[Hypothesis, ...]):
        self.hyps = hyps
        self.size = len(hyps)
        self.token = next(_TOKENS)
        self._away: dict[int, tuple[Trajectory, np.ndarray]] = {}
        self._feasible: dict[tuple[str, ...], np.ndarray] = {}

    def feasible(self, objects: tuple[str, ...] | list[str]) -> np.ndarray:
        """Per hypothesis: can a scene of ``objects`` show it? (memoised per scene)"""
        key = tuple(objects)
        got = self._feasible.get(key)
        if got is None:
            from activeintent.world import Scene

            scene = Scene(objects=list(key))
            got = np.fromiter((h.feasible(scene) for h in self.hyps), bool, self.size)
            if len(self._feasible) > 4096:
                self._feasible.clear()
            self._feasible[key] = got
        return got

    def prefetch(self, states: list[Facts]) -> None:
        """Judge many states at once (hypotheses that run code in a sandbox batch them)."""
        for h in self.hyps:
            h.prefetch(states)

    def judge(self, f: Facts) -> tuple[np.ndarray, np.ndarray]:
        """(satisfied, score) of the state behind ``f`` under every hypothesis."""
        if ("judge", self.token) not in f.memo:  # query selection asks again and again
            for h in self.hyps:
                h.prefetch([f])
        return judge(self.hyps, f, self.token)

    def utility(self, state: WorldState) -> np.ndarray:
        sat, score = self.judge(facts(state))
        return utility(score, sat)

    def first_away(self, traj: Trajectory) -> np.ndarray:
        hit = self._away.get(id(traj))
        if hit is not None and hit[0] is traj:
            return hit[1]
        steps = trajectory_steps(traj)
        for h in self.hyps:
            h.prefetch([f for st in steps for f in st[:2]])
        away = first_away(self.hyps, steps, self.token)
        if len(self._away) > 4096:
            self._away.clear()
        self._away[id(traj)] = (traj, away)  # keeps τ alive so its id is not reused
        return away
