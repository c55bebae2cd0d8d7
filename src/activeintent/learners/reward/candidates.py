"""Candidate plans of the reward learners, each predicted on the symbolic world model.

- ``random_plans``: random sequences of 1–3 generic skills that all succeed;
- ``feature_plans``: for each feature the scene can change, the greedy plan (≤ 2 steps) that
  raises it most, preferring moves that change fewer other features;
- ``planner_plans``: the project's candidate planner (``learners.bayes.candidates``) run on
  the hypothesis prior alone — no answer ever reaches it (experiments/reward-variants/noplanner.py
  leaves them out);
- ``reward_plans``: greedy hill-climbing on a reward vector (the posterior mean), for the
  final answer.
"""

from __future__ import annotations

import numpy as np

from activeintent import ranking
from activeintent.envs.symbolic import symbolic_trajectory
from activeintent.goals.facts import facts, state_key
from activeintent.learners.bayes.belief import Belief
from activeintent.learners.bayes.candidates import Outcome, candidate_plans
from activeintent.learners.bayes.hypotheses import hypothesis_space
from activeintent.learners.reward.features import N_FEATURES, phi
from activeintent.memo import memoized
from activeintent.world import PutAt, PutIn, PutNextTo, PutOn, Skill, WorldState, apply_skill
from activeintent.world.skills import TABLE_POSITIONS


def moves(state: WorldState) -> list[Skill]:
    """Every generic one-block move: into each bowl, onto each clear block, next to each
    object, at each named table position (only blocks with nothing on them move)."""
    f = facts(state)
    out: list[Skill] = []
    clear = [b for b in f.blocks if f.above.get(b) is None]
    for b in clear:
        out += [PutIn(block=b, bowl=w) for w in f.bowls]
        out += [PutOn(block=b, target=t) for t in clear if t != b]
        out += [PutNextTo(block=b, target=o) for o in state.positions if o != b]
        out += [PutAt(block=b, position=p) for p in TABLE_POSITIONS]
    return out


def successors(state: WorldState) -> list[tuple[Skill, WorldState]]:
    """(move, next state) for every move that succeeds and changes the state."""
    return list(_succ_cached(_key(state)))


def _key(state: WorldState) -> tuple:
    return tuple((n, float(p[0]), float(p[1]), float(p[2])) for n, p in state.positions.items())


@memoized(size=4096, why="a state's exact positions: its successors are a pure function of them")
def _succ_cached(key: tuple) -> tuple:
    state = WorldState(positions={n: (x, y, z) for n, x, y, z in key})
    out = []
    for m in moves(state):
        new, fail = apply_skill(state, m)
        if fail is None and new.positions != state.positions:
            out.append((m, new))
    return tuple(out)


def predict(state: WorldState, plan: list[Skill]) -> Outcome:
    return Outcome(list(plan), symbolic_trajectory(state.scene, state, plan))


class Pool:
    """Distinct predicted outcomes (by final state), doing nothing excluded unless asked."""

    def __init__(self, state: WorldState, keep_nothing: bool = False):
        self.state = state
        self.outs: list[Outcome] = []
        self.seen: set[tuple] = set() if keep_nothing else {state_key(facts(state))}

    def extend(self, outs: list[Outcome]) -> None:
        """Add already predicted outcomes (distinct ones only)."""
        for o in outs:
            if o.key not in self.seen:
                self.seen.add(o.key)
                self.outs.append(o)

    def add(self, plan: list[Skill]) -> bool:
        o = predict(self.state, plan)
        if any(not s.ok for s in o.traj.steps):
            return False
        k = o.key
        if k in self.seen:
            return False
        self.seen.add(k)
        self.outs.append(o)
        return True


def random_plans(pool: Pool, rng: np.random.Generator, n: int, max_len: int = 3) -> None:
    for _ in range(n):
        length = int(rng.integers(1, max_len + 1))
        state, plan = pool.state, []
        for _ in range(length):
            succ = successors(state)
            if not succ:
                break
            m, state = succ[int(rng.integers(len(succ)))]
            plan.append(m)
        if plan:
            pool.add(plan)


def feature_plans(pool: Pool, features: np.ndarray, depth: int = 2) -> None:
    """For each feature index in ``features``: the greedy plan raising it (ties: the move that
    changes the other features least, then the first)."""
    root = phi(pool.state)
    level = [(pool.state, [], root)]
    best_plans: dict[int, list[Skill]] = {}
    for _ in range(depth):
        nxt = []
        for state, plan, v0 in level:
            succ = successors(state)
            if not succ:
                continue
            V = np.array([phi(s) for _, s in succ])  # [moves, d]
            D = V - v0
            other = np.abs(D).sum(axis=1)
            for i in features:
                if plan and best_plans.get(int(i)) != plan:
                    continue
                gain = D[:, i]
                if gain.max() <= 1e-9:
                    continue
                j = ranking.argmax(gain - 1e-3 * other)
                best_plans[int(i)] = plan + [succ[j][0]]
                nxt.append((succ[j][1], plan + [succ[j][0]], V[j]))
        # expand each distinct state once
        uniq, seen = [], set()
        for s, p, v in nxt:
            k = _key(s)
            if k not in seen:
                seen.add(k)
                uniq.append((s, p, v))
        level = uniq
    for i in sorted(best_plans):
        pool.add(best_plans[i])


def planner_plans(pool: Pool, rng: np.random.Generator, limit: int = 24, prefixes: bool = True) -> None:
    """The Bayesian learners' planner on the prior over its hypotheses (no answer involved)."""
    hyps, w = _prior()
    feasible = np.fromiter((h.feasible(pool.state.scene) for h in hyps), bool, len(hyps))
    for o in candidate_plans(hyps, w, pool.state, rng, top_k=16, explore=6, prefixes=prefixes,
                             limit=limit, feasible=feasible):
        pool.add(o.plan)


@memoized(size=1, why="no arguments: the length prior over the bayes hypothesis space (seed 0)")
def _prior():
    b = Belief(tuple(hypothesis_space(0)), "length")
    return b.hyps, b.weights


def successor_features(state: WorldState, memo: dict | None = None) -> np.ndarray:
    """φ of every successor of ``state`` [moves, d], in ``successors`` order (memoised in
    ``memo`` by exact state: a test scene's successors are the same at every k)."""
    key = _key(state)
    got = memo.get(key) if memo is not None else None
    if got is None:
        succ = successors(state)
        got = np.array([phi(s) for _, s in succ]) if succ else np.zeros((0, N_FEATURES))
        if memo is not None:
            memo[key] = got
    return got


def reward_plans(pool: Pool, w: np.ndarray, depth: int = 4, memo: dict | None = None) -> None:
    """Greedy ascent on r(s) = w · φ(s) from the scene's layout, every prefix kept."""
    state, plan = pool.state, []
    r = float(w @ phi(state))
    for _ in range(depth):
        succ = successors(state)
        if not succ:
            break
        vals = successor_features(state, memo) @ w
        j = ranking.argmax(vals)
        if not ranking.greater(float(vals[j]), r):
            break
        plan = plan + [succ[j][0]]
        state, r = succ[j][1], float(vals[j])
        pool.add(plan)
