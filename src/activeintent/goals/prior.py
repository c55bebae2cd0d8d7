"""P(z) over the goal language: description length, or a distribution fitted to what people ask.

The length prior (``Goal.bits``) charges every choice point of the grammar a uniform choice.
The fitted prior keeps the grammar's choice points and estimates each one's probabilities from
a corpus of requests translated into the language (data/requests/): Dirichlet-smoothed counts

    P(x | choice point) = (c(x) + α) / (N + α K)          (K choices, N counts at that point)

with one strength α chosen by cross-validation on the corpus (:func:`choose_alpha`). A goal z is
a number of clauses n, the flag "every other block stays", and a set of n distinct clauses;
a clause is a quantifier, a selector (type, then parameter) and a relation (type, parameter), or
a structure (type, parameter) of a selector. Drawn independently, a clause has probability
P(c) = P(kind) × the product of its choices, and

    P(z) = P(n) P(stays) n! Π_i P(c_i) / D_n,      D_n = P(n clauses drawn are all distinct)

(n! orders give the same set), so P(z) is a proper distribution over the language's goals.
L(z) = −log₂ P(z) is what the learners read as ``bits``; α → ∞ gives uniform choices.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from activeintent.goals.goal import MAX_CLAUSES, QUANTS, Each, Form, Goal, parse_goal
from activeintent.goals.nodes import check_language, nodes, spoken
from activeintent.memo import BoundedCache

ALPHAS = (0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0)  # the smoothing strengths tried
# The priors fitted to data/requests, shipped as package data: one per language version.
PACKAGED = {1: "requests.json", 2: "requests-2.json"}


class PriorError(ValueError):
    """A prior file or a corpus that cannot be read; the message names the file and line."""


def choice_points(version: int | None = None) -> dict[str, tuple[str, ...]]:
    """Every choice point of the grammar of language ``version`` (default: the one in force)
    and its choices (plug-in nodes included)."""
    points: dict[str, tuple[str, ...]] = {
        "clauses": tuple(str(n) for n in range(1, MAX_CLAUSES + 1)),
        "stays": ("no", "yes"),
        "kind": ("each", "form"),
        "quantifier": QUANTS,
    }
    for kind in ("selector", "relation", "structure"):
        points[kind] = tuple(nodes(kind, version))
        for key, node in nodes(kind, version).items():
            points[f"{kind}:{key}"] = tuple(node.params)
    return points


def choices_of(goal: Goal) -> list[tuple[str, str]]:
    """The (choice point, choice) pairs of one derivation of ``goal``."""
    out = [("clauses", str(len(goal.clauses))), ("stays", "yes" if goal.stays else "no")]
    for c in goal.clauses:
        if isinstance(c, Form):
            out += [("kind", "form"), ("structure", c.struct), (f"structure:{c.struct}", c.stp)]
        else:
            out += [("kind", "each"), ("quantifier", c.quant), ("relation", c.rel), (f"relation:{c.rel}", c.rp)]
        out += [("selector", c.sel), (f"selector:{c.sel}", c.sp)]
    return out


@dataclass(eq=False)  # compared and hashed by identity: load_prior keeps one per content
class FittedPrior:
    """Counts per choice point and the smoothing strength α; probabilities over the language
    as it is now (a choice the corpus never used gets α alone)."""

    counts: dict[str, dict[str, int]]
    alpha: float
    corpus: str = ""  # sha256 of the translations it was fitted to
    requests: int = 0
    language: int = 1  # the language version whose choice points it is over
    _p: dict[str, dict[str, float]] = field(default_factory=dict, repr=False)
    _norm: tuple[float, float, float] | None = field(default=None, repr=False)

    def p(self, point: str) -> dict[str, float]:
        got = self._p.get(point)
        if got is None:
            choices = choice_points(self.language)[point]
            seen = self.counts.get(point, {})
            total = sum(seen.get(x, 0) for x in choices) + self.alpha * len(choices)
            got = self._p[point] = {x: (seen.get(x, 0) + self.alpha) / total for x in choices}
        return got

    def _power_sum(self, k: int) -> float:
        """Σ_c P(c)^k over every clause of the language (the factors are independent)."""
        def sel() -> float:
            ps = self.p("selector")
            return sum(ps[s] ** k * sum(v ** k for v in self.p(f"selector:{s}").values()) for s in ps)

        def rel() -> float:
            pr = self.p("relation")
            return sum(pr[r] ** k * sum(v ** k for v in self.p(f"relation:{r}").values()) for r in pr)

        def struct() -> float:
            pst = self.p("structure")
            return sum(pst[s] ** k * sum(v ** k for v in self.p(f"structure:{s}").values()) for s in pst)

        kind, quant = self.p("kind"), self.p("quantifier")
        each = kind["each"] ** k * sum(v ** k for v in quant.values()) * sel() * rel()
        return each + kind["form"] ** k * struct() * sel()

    def distinct(self, n: int) -> float:
        """D_n: the probability that n clauses drawn independently are all different."""
        if self._norm is None:
            self._norm = (1.0, self._power_sum(2), self._power_sum(3))
        _, s2, s3 = self._norm
        return {1: 1.0, 2: 1.0 - s2, 3: 1.0 - 3.0 * s2 + 2.0 * s3}[n]

    def clause_log2(self, clause: Each | Form) -> float:
        g = Goal((clause,))
        return sum(math.log2(self.p(point)[x]) for point, x in choices_of(g)[2:])

    def bits(self, goal: Goal) -> float:
        """L(z) = −log₂ P(z) under the fitted prior."""
        n = len(goal.clauses)
        if len(set(c.key for c in goal.clauses)) != n:
            return math.inf  # a goal names each clause once
        log2p = (math.log2(self.p("clauses")[str(n)]) + math.log2(self.p("stays")["yes" if goal.stays else "no"])
                 + math.log2(math.factorial(n)) - math.log2(self.distinct(n)))
        return -(log2p + sum(self.clause_log2(c) for c in goal.clauses))

    @property
    def tag(self) -> str:
        """A short name of this prior's content (cache keys, records)."""
        return hashlib.sha256(json.dumps(self.to_json(), sort_keys=True).encode()).hexdigest()[:12]

    def to_json(self) -> dict:
        out = {"kind": "fitted", "alpha": self.alpha, "corpus": self.corpus, "requests": self.requests,
               "counts": {k: dict(sorted(v.items())) for k, v in sorted(self.counts.items())}}
        if self.language != 1:  # files of language 1 predate the field (their tags stay)
            out["language"] = self.language
        return out

    @classmethod
    def from_json(cls, data: dict, where: str = "prior") -> FittedPrior:
        try:
            if data.get("kind") != "fitted":
                raise PriorError(f"{where}: not a fitted prior (kind {data.get('kind')!r})")
            return cls({k: {x: int(c) for x, c in v.items()} for k, v in data["counts"].items()},
                       float(data["alpha"]), data.get("corpus", ""), int(data.get("requests", 0)),
                       check_language(int(data.get("language", 1))))
        except (KeyError, TypeError, ValueError, AttributeError) as err:
            if isinstance(err, PriorError):
                raise
            raise PriorError(f"{where}: not a prior file written by `prior fit` ({err})") from None


def goal_bits(goal: Goal, prior: FittedPrior | None) -> float:
    """L(z) under ``prior``; None is the length prior (the goal's own bits)."""
    return goal.bits if prior is None else prior.bits(goal)


def count(goals: Iterable[Goal]) -> dict[str, dict[str, int]]:
    tally: dict[str, Counter] = {}
    for g in goals:
        for point, x in choices_of(g):
            tally.setdefault(point, Counter())[x] += 1
    return {k: dict(v) for k, v in tally.items()}


def fit(goals: list[Goal], alpha: float, corpus: str = "") -> FittedPrior:
    """The prior of ``goals`` over the language in force."""
    if not alpha > 0:
        raise ValueError(f"the smoothing strength must be > 0 (got {alpha}): a goal nobody asked for stays possible")
    return FittedPrior(count(goals), alpha, corpus, len(goals), spoken())


def folds(n: int, k: int, seed: int = 0) -> list[np.ndarray]:
    order = np.random.default_rng(seed).permutation(n)
    return [order[i::k] for i in range(k)]


def choose_alpha(goals: list[Goal], alphas: tuple[float, ...] = ALPHAS, k: int = 5, seed: int = 0) -> float:
    """The α with the fewest held-out bits per goal over k folds of ``goals``."""
    parts = folds(len(goals), k, seed)
    scores = []
    for a in alphas:
        held = []
        for i, test in enumerate(parts):
            train = [goals[j] for p, part in enumerate(parts) if p != i for j in part]
            prior = fit(train, a)
            held += [prior.bits(goals[j]) for j in test]
        scores.append(float(np.mean(held)))
    return alphas[int(np.argmin(scores))]


def nested_cv(goals: list[Goal], k: int = 5, seed: int = 0) -> dict:
    """Bits per request on held-out folds: the fitted prior (α chosen inside each training fold)
    against the length prior. Returns the means and per-fold α."""
    parts = folds(len(goals), k, seed)
    fitted, length, alphas = [], [], []
    for i, test in enumerate(parts):
        train = [goals[j] for p, part in enumerate(parts) if p != i for j in part]
        a = choose_alpha(train, k=k, seed=seed + 1)
        prior = fit(train, a)
        alphas.append(a)
        fitted += [prior.bits(goals[j]) for j in test]
        length += [goals[j].bits for j in test]
    diff = np.array(length) - np.array(fitted)
    half = 1.96 * diff.std(ddof=1) / math.sqrt(len(diff)) if len(diff) > 1 else float("nan")
    return {"requests": len(goals), "folds": k, "fitted_bits": round(float(np.mean(fitted)), 3),
            "length_bits": round(float(np.mean(length)), 3), "saved_bits": round(float(diff.mean()), 3),
            "saved_bits_95": [round(float(diff.mean() - half), 3), round(float(diff.mean() + half), 3)],
            "alphas": alphas}


def read_corpus(path: Path) -> tuple[list[Goal], str]:
    """The goals of a corpus file (JSON lines with a "goal" key: a goal of the language, or null
    for a request it cannot express) and the file's sha256. A malformed line is an error naming it."""
    try:
        raw = Path(path).read_bytes()
    except OSError as err:
        raise PriorError(f"cannot read the corpus {path}: {err.strerror or err}") from None
    goals = []
    for no, line in enumerate(raw.decode("utf-8", errors="replace").splitlines(), 1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
            key = row.get("goal") if isinstance(row, dict) else None
            if not isinstance(row, dict) or "goal" not in row:
                raise ValueError('a JSON object with a "goal" key (a goal of the language, or null)')
            if key is None:
                continue
            goal = parse_goal(str(key))
            if not all(_known(c) for c in goal.clauses):
                raise ValueError(f"{key!r} is not a goal of the language (`hypotheses --language` lists it)")
        except (ValueError, KeyError, IndexError) as err:
            raise PriorError(f"{path}, line {no}: expected {err}" if "JSON object" in str(err)
                             else f"{path}, line {no}: {err}") from None
        goals.append(goal)
    if not goals:
        raise PriorError(f"{path}: no translated request (every line's goal is null or the file is empty)")
    return goals, hashlib.sha256(raw).hexdigest()


def _known(c) -> bool:
    def has(kind: str, key: str, param: str) -> bool:
        return key in nodes(kind) and param in nodes(kind)[key].params

    if not has("selector", c.sel, c.sp):
        return False
    if isinstance(c, Form):
        return has("structure", c.struct, c.stp)
    return c.quant in QUANTS and has("relation", c.rel, c.rp)


def load_prior(name: str, language: int | None = None) -> FittedPrior | None:
    """``length`` / ``uniform``: None (the goal's own bits, or no prior); ``fitted``: the prior
    shipped with the package for language ``language`` (default: the one in force), fitted to
    data/requests; ``file:PATH``: one written by `prior fit` (over the same language)."""
    language = spoken() if language is None else check_language(language)
    if name in ("length", "uniform"):
        return None
    if name == "fitted":
        text = resources.files("activeintent.goals").joinpath("priors", PACKAGED[language]).read_text()
        return _cached(text, "the packaged fitted prior")
    if name.startswith("file:"):
        path = Path(name[5:])
        try:
            text = path.read_text()
        except OSError as err:
            raise PriorError(f"--prior {name}: cannot read {path}: {err.strerror or err}") from None
        prior = _cached(text, str(path))
        if prior.language != language:
            raise PriorError(f"--prior {name}: fitted over language {prior.language}, the run speaks language "
                             f"{language}; fit it again with `activeintent prior fit`")
        return prior
    raise PriorError(f"unknown prior {name!r}; valid priors: length, uniform, fitted, file:PATH")


# Parsed priors by their JSON text (a pure function of it): the packaged ones and a few files.
_LOADED: BoundedCache[str, FittedPrior] = BoundedCache(32)


def _cached(text: str, where: str) -> FittedPrior:
    got = _LOADED.get(text)
    if got is None:
        try:
            data = json.loads(text)
        except ValueError as err:
            raise PriorError(f"{where}: not JSON ({err})") from None
        got = _LOADED.put(text, FittedPrior.from_json(data, where))
    return got


__all__ = ["ALPHAS", "FittedPrior", "PriorError", "choices_of", "choose_alpha", "choice_points", "fit", "goal_bits",
           "load_prior", "nested_cv", "read_corpus"]
