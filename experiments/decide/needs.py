"""What the intention needs of a scene's objects, learned from "new scene" answers.

A goal's own check says which objects it refers to, but a person may refuse a scene for a reason
no goal of the space states ("every block must have a rainbow colour", "at least four blocks").
Beside the belief over z the learner keeps a belief v over requirements R on the object set:
conjunctions of at most ``MAX_LITERALS`` literals (``LITERALS``: at least 3 / 4 blocks, at least
2 / 3 bowls, a block of colour c, no block of colour c, a bowl of colour c, every block's own
bowl, a warm / cool block, no warm / cool block; with ``counts``, also for every selector of the
goal language "at least 1 / 2 blocks it picks", where that says something the others do not, such
as "two cool blocks"). Prior from description length: the number of literals k is geometric, P(k) ∝ 2^-(k+1),
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

import functools
import itertools
import math

import numpy as np

from activeintent.goals.language import NODES, nodes
from activeintent.learners.bayes.hypotheses import random_scene
from activeintent.world import COLOR_NAMES, WARM_COLORS, Scene
from activeintent.world.scene import color_of, kind_of

MAX_LITERALS = 3


def _base_literals() -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = [("blocks>=", 3), ("blocks>=", 4), ("bowls>=", 2), ("bowls>=", 3)]
    out += [("block", c) for c in COLOR_NAMES] + [("no-block", c) for c in COLOR_NAMES]
    out += [("bowl", c) for c in COLOR_NAMES] + [("own-bowls", None)]
    out += [("class", "warm"), ("class", "cool"), ("no-class", "warm"), ("no-class", "cool")]
    return out


def _truth(literals: list[tuple[str, object]], objects: tuple[str, ...]) -> np.ndarray:
    blocks = [o for o in objects if kind_of(o) == "block"]
    colours = {color_of(b) for b in blocks}
    classes = {"warm" if c in WARM_COLORS else "cool" for c in colours}
    bowls = tuple(o for o in objects if kind_of(o) == "bowl")
    bowl_colours = {color_of(o) for o in bowls}
    out = []
    for kind, arg in literals:
        if kind == "blocks>=":
            out.append(len(blocks) >= arg)  # type: ignore[operator]
        elif kind == "bowls>=":
            out.append(len(bowls) >= arg)  # type: ignore[operator]
        elif kind == "block":
            out.append(arg in colours)
        elif kind == "no-block":
            out.append(arg not in colours)
        elif kind == "bowl":
            out.append(arg in bowl_colours)
        elif kind == "class":
            out.append(arg in classes)
        elif kind == "no-class":
            out.append(arg not in classes)
        elif kind == "picks>=":
            sel, p, n = arg  # type: ignore[misc]
            node = NODES["selector"][sel]
            out.append(sum(node.pick(b, bowls, p) for b in blocks) >= n)
        else:
            out.append(colours <= bowl_colours)
    return np.array(out, bool)


_COUNT_BANK = 400  # seeded scenes on which a count literal must vary and differ from the others


@functools.cache
def count_literals(language: int = 1) -> tuple[tuple[str, object], ...]:
    """"At least n blocks picked by selector (s, p)" for n = 1, 2 and every selector of the goal
    language ``language`` (its version), each kept only if on a seeded bank of random scenes it is sometimes true, sometimes
    false, and unlike every literal kept before it, base literals included (made on first use)."""
    rng = np.random.default_rng(0)
    scenes = [tuple(random_scene(rng).objects) for _ in range(_COUNT_BANK)]
    seen = {row.tobytes() for row in np.array([_truth(LITERALS, s) for s in scenes]).T}
    out: list[tuple[str, object]] = []
    for sel, node in nodes("selector", language).items():
        for p in node.params:
            for n in (1, 2):
                lit = ("picks>=", (sel, p, n))
                row = np.array([_truth([lit], s)[0] for s in scenes])
                if row.all() or not row.any() or row.tobytes() in seen:
                    continue
                seen.add(row.tobytes())
                out.append(lit)
    return tuple(out)


LITERALS = _base_literals()


class Needs:
    """The belief v over requirements R (index sets of literals; the empty set: no requirement)."""

    def __init__(self, new_scene_error: float, counts: bool = False, language: int = 1):
        self.error = new_scene_error
        self.counts = counts
        self.literals = LITERALS + list(count_literals(language)) if counts else LITERALS
        n = len(self.literals)
        sets = [()] + [c for k in range(1, MAX_LITERALS + 1) for c in itertools.combinations(range(n), k)]
        self.size = len(sets)
        self.index = np.full((self.size, MAX_LITERALS), n)  # n: a sentinel literal that always holds
        for i, s in enumerate(sets):
            self.index[i, :len(s)] = s
        k = np.array([len(s) for s in sets])
        log_p_k = -(k + 1) * math.log(2) - np.log([math.comb(n, int(j)) for j in k])
        self.log_v = log_p_k - np.logaddexp.reduce(log_p_k)
        self._fails: dict[tuple[str, ...], np.ndarray] = {}
        self._weights: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def weights(self) -> np.ndarray:
        if self._weights is None or self._weights[0] is not self.log_v:  # kept while log_v is: scene design asks often
            self._weights = (self.log_v, np.exp(self.log_v - np.logaddexp.reduce(self.log_v)))
        return self._weights[1]

    def fails(self, objects: tuple[str, ...]) -> np.ndarray:
        """Per R: does a scene of these objects fail it?"""
        got = self._fails.get(objects)
        if got is None:
            truth = np.append(_truth(self.literals, objects), True)
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
        self.log_v = self.log_v - np.logaddexp.reduce(self.log_v)

    def top(self, n: int = 3) -> list[tuple[str, float]]:
        w = self.weights
        order = np.argsort(-w, kind="stable")[:n]
        return [(self.describe(int(i)), round(float(w[i]), 4)) for i in order]

    def describe(self, i: int) -> str:
        lits = [self.literals[j] for j in self.index[i] if j < len(self.literals)]
        return " & ".join(_word(k, a) for k, a in lits) or "nothing"


def _word(kind: str, arg: object) -> str:
    if kind == "picks>=":
        sel, p, n = arg  # type: ignore[misc]
        return f"{n}+ {sel}:{p}"
    return f"{kind}{arg}" if kind.endswith("=") else kind if arg is None else f"{kind}:{arg}"


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
