"""The :class:`activeintent.signals.Judge` of the hypothesis space: every z judges at once."""

from __future__ import annotations

import itertools

import numpy as np

from activeintent.goals.facts import Facts, facts
from activeintent.learners.bayes.hypotheses import Hypothesis
from activeintent.memo import BoundedCache, IdentityCache
from activeintent.world import Scene, WorldState
from activeintent.world.trajectory import Trajectory

_TOKENS = itertools.count()


class _Clauses:
    """The grammar hypotheses of a tuple as indices into their distinct clauses, so that a state
    is judged once per clause and combined in numpy (the same arithmetic, in the same order, as
    :meth:`Hypothesis.holds_f` / ``score_f`` / ``moved_off``). Hypotheses that judge by their own
    methods (model-proposed ones) are asked one by one, as before."""

    def __init__(self, hyps: tuple[Hypothesis, ...]):
        by_clauses = [_judged_by_clauses(h) for h in hyps]
        grammar = [i for i, yes in enumerate(by_clauses) if yes]
        self.grammar = np.array(grammar, dtype=int)
        self.own = [i for i, yes in enumerate(by_clauses) if not yes]
        index: dict[tuple[str, str], int] = {}
        self.clauses = []
        width = max((len(hyps[i].clauses) for i in grammar), default=0)
        self.idx = np.full((len(grammar), width), -1, dtype=int)  # -1: no clause (a pad entry)
        for row, i in enumerate(grammar):
            for j, c in enumerate(hyps[i].clauses):
                key = (c.selector, c.behaviour.key)  # judge_f's memo key: one verdict per key
                if key not in index:
                    index[key] = len(self.clauses)
                    self.clauses.append(c)
                self.idx[row, j] = index[key]

    def judge(self, f: Facts) -> tuple[np.ndarray, np.ndarray]:
        """(satisfied, score) of the grammar hypotheses, in the order of ``grammar``."""
        verdicts = [c.judge_f(f) for c in self.clauses] + [(True, 0.0, 0)]  # the pad last
        holds = np.array([v[0] for v in verdicts], dtype=bool)
        score = np.array([v[1] for v in verdicts], dtype=float)
        size = np.array([v[2] for v in verdicts], dtype=int)
        sat = holds[self.idx].all(axis=1)
        total = np.zeros(len(self.idx))
        for j in range(self.idx.shape[1]):  # clause by clause: the float sums of score_f
            total = total + score[self.idx[:, j]] * size[self.idx[:, j]]
        n = size[self.idx].sum(axis=1)
        return sat, np.where(n > 0, total / np.maximum(n, 1), 1.0)

    def feasible(self, objects: tuple[str, ...], blocks: list[str]) -> np.ndarray:
        """Per grammar hypothesis: can a scene of ``objects`` show it? (every clause has a
        group there that its behaviour can be shown on, as :meth:`Hypothesis.feasible`)"""
        ok = np.array([bool(g) and c.leaf.feasible(objects, g) for c in self.clauses
                       for g in (c.group(blocks),)] + [True], dtype=bool)
        return ok[self.idx].all(axis=1)

    def moved_off(self, fb: Facts, fa: Facts, block: str, rows: np.ndarray) -> np.ndarray:
        """Per grammar hypothesis in ``rows``: did moving ``block`` leave a place z allows?"""
        off = np.zeros(len(self.clauses) + 1, dtype=bool)
        for ci in np.unique(self.idx[rows]):
            if ci < 0:
                continue
            c = self.clauses[ci]
            g = c.group_f(fa)
            off[ci] = block in g and not c.leaf.moved_ok(fb, fa, g, block)
        return off[self.idx[rows]].any(axis=1)


def _judged_by_clauses(h: Hypothesis) -> bool:
    t = type(h)
    return (t.holds_f is Hypothesis.holds_f and t.score_f is Hypothesis.score_f
            and t.moved_off is Hypothesis.moved_off and t.feasible is Hypothesis.feasible and bool(h.clauses))


# by the hypothesis set's token (one per set of hypotheses)
_COMPILED: BoundedCache[object, _Clauses] = BoundedCache(64)


def _compiled(hyps: tuple[Hypothesis, ...], token: object) -> _Clauses:
    return _COMPILED.get_or_make(token, lambda: _Clauses(hyps))


def judge(hyps: tuple[Hypothesis, ...], f: Facts, token: object = None) -> tuple[np.ndarray, np.ndarray]:
    """(satisfied, score) of one state under every hypothesis, memoised on the facts under
    ``token`` (unique per judge: an id() could be reused by a later tuple)."""
    if token is None:
        token = tuple(h.name for h in hyps)
    key = ("judge", token)
    got = f.memo.get(key)
    if got is None:
        comp = _compiled(hyps, token)
        sat = np.zeros(len(hyps), dtype=bool)
        score = np.zeros(len(hyps), dtype=float)
        sat[comp.grammar], score[comp.grammar] = comp.judge(f)
        for i in comp.own:
            sat[i], score[i] = hyps[i].holds_f(f), hyps[i].score_f(f)
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
    if token is None:
        token = tuple(h.name for h in hyps)
    comp = _compiled(hyps, token)
    out = np.full(len(hyps), -1)
    for k, (fb, fa, block, ok) in enumerate(steps):
        todo = out < 0
        if not todo.any():
            break
        if fb is fa:
            continue
        _, sb = judge(hyps, fb, token)
        _, sa = judge(hyps, fa, token)
        away = sa < sb - 1e-9
        if ok:
            rows = np.flatnonzero(todo[comp.grammar] & ~away[comp.grammar])
            away[comp.grammar[rows]] = comp.moved_off(fb, fa, block, rows)
            for i in comp.own:
                if todo[i] and not away[i]:
                    away[i] = hyps[i].moved_off(fb, fa, block)
        out[todo & away] = k
    return out


class HypothesisJudge:
    """Judges outcomes under every hypothesis of H (n = |H|)."""

    def __init__(self, hyps: tuple[Hypothesis, ...]):
        self.hyps = hyps
        self.size = len(hyps)
        self.token = next(_TOKENS)
        self._away: IdentityCache[np.ndarray] = IdentityCache(4096)  # per τ shown
        self._feasible: BoundedCache[tuple[str, ...], np.ndarray] = BoundedCache(4096)  # per scene's objects
        # hypotheses that judge in batches (model-proposed code); the others' prefetch does nothing
        self._batched = [h for h in hyps if type(h).prefetch is not Hypothesis.prefetch]

    def feasible(self, objects: tuple[str, ...] | list[str]) -> np.ndarray:
        """Per hypothesis: can a scene of ``objects`` show it? (memoised per scene)"""
        key = tuple(objects)
        got = self._feasible.get(key)
        if got is None:
            scene = Scene(objects=list(key))
            comp = _compiled(self.hyps, self.token)
            got = np.zeros(self.size, dtype=bool)
            got[comp.grammar] = comp.feasible(tuple(scene.objects), scene.blocks)
            for i in comp.own:
                got[i] = self.hyps[i].feasible(scene)
            self._feasible.put(key, got)
        return got

    def prefetch(self, states: list[Facts]) -> None:
        """Judge many states at once (hypotheses that run code in a sandbox batch them)."""
        for h in self._batched:
            h.prefetch(states)

    def judge(self, f: Facts) -> tuple[np.ndarray, np.ndarray]:
        """(satisfied, score) of the state behind ``f`` under every hypothesis."""
        if ("judge", self.token) not in f.memo:  # query selection asks again and again
            for h in self._batched:
                h.prefetch([f])
        return judge(self.hyps, f, self.token)

    def utility(self, state: WorldState) -> np.ndarray:
        sat, score = self.judge(facts(state))
        return utility(score, sat)

    def step_away(self, fb: Facts, fa: Facts, block: str, ok: bool = True) -> np.ndarray:
        """Per z: does moving ``block`` (facts before → after) move away from z?"""
        for h in self._batched:
            h.prefetch([fb, fa])
        return first_away(self.hyps, [(fb, fa, block, ok)], self.token) == 0

    def first_away(self, traj: Trajectory) -> np.ndarray:
        return self._away.get_or_make(traj, lambda: self._first_away(traj))

    def _first_away(self, traj: Trajectory) -> np.ndarray:
        steps = trajectory_steps(traj)
        for h in self._batched:
            h.prefetch([f for st in steps for f in st[:2]])
        return first_away(self.hyps, steps, self.token)
