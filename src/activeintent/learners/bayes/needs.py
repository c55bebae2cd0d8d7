"""What the intention needs of a scene's objects, learned from "new scene" answers.

A goal's own check says which objects it refers to, but a person may refuse a scene for a reason
no goal of the space states ("every block must have a rainbow colour", "at least four blocks").
Beside the belief over z the learner keeps a belief v over requirements R on the object set:
conjunctions of at most ``MAX_LITERALS`` literals (``LITERALS``: at least 3 / 4 blocks, at least
2 / 3 bowls, a block of colour c, no block of colour c, a bowl of colour c, every block's own
bowl, a warm / cool block, no warm / cool block). Prior from description length: the number of literals k is geometric, P(k) ∝ 2^-(k+1),
and the k literals are uniform among the sets of that size.

Mean-field answer model (z and R independent): with ε the assumed error of a "new scene" answer,
m = Σ_z w_z 1[z can be shown in s] and q(s) = Σ_R v_R 1[R fails on s],

    P(new scene | R) = 1 − ε                    if R fails on s
                       (1 − ε)(1 − m) + ε m     otherwise
    P(new scene | z) = 1 − ε                    if z cannot be shown in s
                       q (1 − ε) + (1 − q) ε     otherwise

(q = 0 gives the answer model of the learners without this belief).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from activeintent.world import COLOR_NAMES, WARM_COLORS, Scene
from activeintent.world.scene import color_of, kind_of

MAX_LITERALS = 3


def _literals() -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = [("blocks>=", 3), ("blocks>=", 4), ("bowls>=", 2), ("bowls>=", 3)]
    out += [("block", c) for c in COLOR_NAMES] + [("no-block", c) for c in COLOR_NAMES]
    out += [("bowl", c) for c in COLOR_NAMES] + [("own-bowls", None)]
    out += [("class", "warm"), ("class", "cool"), ("no-class", "warm"), ("no-class", "cool")]
    return out


LITERALS = _literals()


def literal_truth(objects: tuple[str, ...]) -> np.ndarray:
    """Which literals hold for a scene of these objects."""
    blocks = {color_of(o) for o in objects if kind_of(o) == "block"}
    classes = {"warm" if c in WARM_COLORS else "cool" for c in blocks}
    bowls = {color_of(o) for o in objects if kind_of(o) == "bowl"}
    n_blocks = sum(kind_of(o) == "block" for o in objects)
    n_bowls = sum(kind_of(o) == "bowl" for o in objects)
    out = []
    for kind, arg in LITERALS:
        if kind == "blocks>=":
            out.append(n_blocks >= arg)
        elif kind == "bowls>=":
            out.append(n_bowls >= arg)
        elif kind == "block":
            out.append(arg in blocks)
        elif kind == "no-block":
            out.append(arg not in blocks)
        elif kind == "bowl":
            out.append(arg in bowls)
        elif kind == "class":
            out.append(arg in classes)
        elif kind == "no-class":
            out.append(arg not in classes)
        else:
            out.append(blocks <= bowls)
    return np.array(out, bool)


class Needs:
    """The belief v over requirements R (index sets of literals; the empty set: no requirement)."""

    def __init__(self, new_scene_error: float):
        self.error = new_scene_error
        sets = [()] + [c for k in range(1, MAX_LITERALS + 1) for c in itertools.combinations(range(len(LITERALS)), k)]
        n = len(LITERALS)
        self.size = len(sets)
        self.index = np.full((self.size, MAX_LITERALS), n)  # n: a sentinel literal that always holds
        for i, s in enumerate(sets):
            self.index[i, :len(s)] = s
        k = np.array([len(s) for s in sets])
        log_p_k = -(k + 1) * math.log(2) - np.log([math.comb(n, int(j)) for j in k])
        self.log_v = log_p_k - np.logaddexp.reduce(log_p_k)
        self._fails: dict[tuple[str, ...], np.ndarray] = {}

    @property
    def weights(self) -> np.ndarray:
        return np.exp(self.log_v - np.logaddexp.reduce(self.log_v))

    def fails(self, objects: tuple[str, ...]) -> np.ndarray:
        """Per R: does a scene of these objects fail it?"""
        got = self._fails.get(objects)
        if got is None:
            truth = np.append(literal_truth(objects), True)
            got = self._fails[objects] = ~truth[self.index].all(axis=1)
        return got

    def refuse(self, scene: Scene | tuple[str, ...]) -> float:
        """q(s): the belief's chance that the scene lacks what the intention needs."""
        objects = tuple(scene.objects) if isinstance(scene, Scene) else tuple(scene)
        return float(self.weights @ self.fails(objects))

    def draw(self, rng: np.random.Generator) -> int:
        """One requirement R drawn from v (its index)."""
        return int(rng.choice(self.size, p=self.weights))

    def update(self, objects: tuple[str, ...], new_scene: bool, shown: float) -> None:
        """Bayes' rule for one answer; ``shown`` = m, the z belief's P(shown) before it."""
        e = self.error
        p_new_ok = (1 - e) * (1 - shown) + e * shown
        p_new = np.where(self.fails(tuple(objects)), 1 - e, p_new_ok)
        lik = p_new if new_scene else 1 - p_new
        self.log_v = self.log_v + np.log(np.clip(lik, 1e-300, None))
        self.log_v -= np.logaddexp.reduce(self.log_v)

    def top(self, n: int = 3) -> list[tuple[str, float]]:
        w = self.weights
        order = np.argsort(-w, kind="stable")[:n]
        return [(self.describe(int(i)), round(float(w[i]), 4)) for i in order]

    def describe(self, i: int) -> str:
        lits = [LITERALS[j] for j in self.index[i] if j < len(LITERALS)]
        return " & ".join(f"{k}{a}" if k.endswith("=") else k if a is None else f"{k}:{a}"
                          for k, a in lits) or "nothing"


def p_new_scene(feasible: np.ndarray, error: float, refuse: float = 0.0) -> np.ndarray:
    """P(new scene | z) per hypothesis (the model above; ``refuse`` = q(s))."""
    if refuse == 0.0:
        return np.where(feasible, error, 1 - error)
    return np.where(feasible, refuse * (1 - error) + (1 - refuse) * error, 1 - error)


def p_answered(feasible: np.ndarray, error: float, refuse: float = 0.0) -> np.ndarray:
    """1 − P(new scene | z): the user answers about what was shown (written out for q = 0, so the
    learners without a needs belief keep their exact values)."""
    if refuse == 0.0:
        return np.where(feasible, 1 - error, error)
    return 1 - p_new_scene(feasible, error, refuse)
