"""The hypothesis space H: a small compositional grammar of intentions z.

A hypothesis is one or two *clauses*; a clause says what a set of blocks (all blocks, the
warm-coloured ones or the cool-coloured ones, see ``world.colors``) should do, by a
*behaviour*: a leaf of the goal language (``goals.recipes``) — a relation every block of the
group satisfies, or a structure the group takes — under the grammar's name and wording.

    H      → all: B_all | class: B_class | warm: B_pair, cool: B_pair
    class  → warm | cool

Each hypothesis is an :class:`Intention`, so it can also serve as a hidden user intention.
Its prior is the probability of generating it from the grammar with uniform choices at every
node: P(h) = 2^(-L(h)), L = description length in bits (docs/bayes.md). Hypotheses that
agree on every state of a bank of feasible scenes are merged (the simplest one is kept).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from activeintent.goals.facts import Facts, facts, is_cool, is_warm
from activeintent.goals.planning import run
from activeintent.goals.recipes import (
    EveryBlock,
    FlatDown,
    Gather,
    IntoArea,
    IntoCorners,
    IntoOneBowl,
    Leaf,
    LineUp,
    OnePerBowl,
    Stack,
    TwoStacks,
)
from activeintent.goals.relations import (
    Flat,
    InBowl,
    InCell,
    InNamedBowl,
    InRegion,
    NextTo,
    OnTable,
)
from activeintent.goals.structures import (
    Cluster,
    Column,
    Corners,
    OneBowl,
    Row,
    SeparateBowls,
    Tower,
    TowerOnBlock,
    TwoTowersAnyHeights,
)
from activeintent.intentions.base import Intention
from activeintent.memo import BoundedCache, memoized
from activeintent.world import COLOR_NAMES, Scene, Skill, WorldState, layout, sample_scene

SELECTORS = {
    "all": lambda b: True,
    "warm": is_warm,
    "cool": is_cool,
}
SUBJECTS = {
    "all": "the blocks",
    "warm": "the warm-coloured blocks (red, orange, yellow, pink, brown)",
    "cool": "the cool-coloured blocks (blue, green, purple, cyan, gray)",
}
# The grammar's regions of the table — its nine cells (world.skills.TABLE_POSITIONS) and its
# halves — as the language says them: corners and halves are regions, the other cells cells.
_REGION, _CELL = InRegion(), InCell()
# Hypothesis.plans by (z, variants, positions); a hypothesis hashes by identity, so a key
# keeps its z alive and never matches another one.
_PLANS: BoundedCache[tuple, list[list[Skill]]] = BoundedCache(30000)
REGIONS = {
    "top left corner": (_REGION, "back left corner"), "top side": (_CELL, "top side"),
    "top right corner": (_REGION, "back right corner"), "left side": (_CELL, "left side"),
    "middle": (_CELL, "middle"), "right side": (_CELL, "right side"),
    "bottom left corner": (_REGION, "front left corner"), "bottom side": (_CELL, "bottom side"),
    "bottom right corner": (_REGION, "front right corner"),
    "left half": (_REGION, "left half"), "right half": (_REGION, "right half"),
    "top half": (_REGION, "back half"), "bottom half": (_REGION, "front half"),
}


@dataclass(frozen=True)
class Behaviour:
    """B: what a group should do — a leaf of the goal language (its meaning, judge and plans)
    under the grammar's name (``family``, ``param``) and wording ("{s}": the subject, "{p}":
    the parameter)."""

    family: str
    wording: str
    leaf: Leaf
    param: str | None = None

    @property
    def key(self) -> str:
        return self.family + (f"[{self.param}]" if self.param else "")

    def phrase(self, subject: str) -> str:
        return self.wording.format(s=subject, p=self.param)


@dataclass(frozen=True)
class Clause:
    selector: str  # "all" | "warm" | "cool"
    behaviour: Behaviour

    @property
    def leaf(self) -> Leaf:
        return self.behaviour.leaf

    def group(self, blocks: tuple[str, ...] | list[str]) -> tuple[str, ...]:
        sel = SELECTORS[self.selector]
        skip = self.leaf.excluded()
        return tuple(b for b in blocks if sel(b) and b != skip)

    @cached_property
    def _judge_key(self) -> tuple:  # built once: judge_f runs ~10^5 times per episode
        return ("clause", self.selector, self.behaviour.key)

    @cached_property
    def _group_key(self) -> tuple:
        return (self.selector, self.leaf.excluded())

    def judge_f(self, f: Facts) -> tuple[bool, float, int]:
        """(holds, score, group size) on ``f``, memoised: many hypotheses share a clause."""
        key = self._judge_key
        got = f.memo.get(key)
        if got is None:
            g = self.group_f(f)
            got = f.memo[key] = (*self.leaf.judge(f, g), len(g))
        return got

    def group_f(self, f: Facts) -> tuple[str, ...]:
        key = self._group_key
        g = f.memo.get(key)
        if g is None:
            g = f.memo[key] = self.group(f.blocks)
        return g


class Hypothesis(Intention):
    """One z: clauses, a sentence, a prior (from its description length) and a planner."""

    def __init__(self, clauses: tuple[Clause, ...], bits: float, description: str | None = None):
        self.clauses = clauses
        self.bits = bits
        self.name = "+".join(f"{c.selector}:{c.behaviour.key}" for c in clauses)
        self.description = description or self._describe()

    def _describe(self) -> str:
        parts = []
        for c in self.clauses:
            subject = SUBJECTS[c.selector]
            if c.leaf.excluded():
                subject = "the other blocks" if c.selector == "all" else f"the other {subject[4:]}"
            parts.append(c.behaviour.phrase(subject))
        text = " and ".join(parts)
        if len(self.clauses) == 1 and self.clauses[0].selector != "all":
            text += "; the other blocks may be anywhere"
        return text[0].upper() + text[1:] + "."

    # -- judging states (Facts versions are used by the learner in bulk) --

    def holds_f(self, f: Facts) -> bool:
        return all(c.judge_f(f)[0] for c in self.clauses)

    def score_f(self, f: Facts) -> float:
        total, n = 0.0, 0
        for c in self.clauses:
            _, score, size = c.judge_f(f)
            total += score * size
            n += size
        return total / n if n else 1.0

    def prefetch(self, states: list[Facts]) -> None:
        """Judge many states at once (hypotheses that run code in a sandbox batch them)."""

    def satisfied(self, state: WorldState) -> bool:
        return self.holds_f(facts(state))

    def score(self, state: WorldState) -> float:
        return self.score_f(facts(state))

    def moves_away_f(self, fb: Facts, fa: Facts, block: str) -> bool:
        """Did moving ``block`` (facts before → after) move away from z?"""
        return self.score_f(fa) < self.score_f(fb) - 1e-9 or self.moved_off(fb, fa, block)

    def moved_off(self, fb: Facts, fa: Facts, block: str) -> bool:
        """Is the moved block's new place inconsistent with z (the score aside)?"""
        for c in self.clauses:
            g = c.group_f(fa)
            if block in g and not c.leaf.moved_ok(fb, fa, g, block):
                return True
        return False

    def step_moves_away(self, before: WorldState, after: WorldState, step: Skill) -> bool:
        if before.positions == after.positions:  # failed step: nothing moved
            return False
        return self.moves_away_f(facts(before), facts(after), step.block)

    # -- scenes and plans --

    def feasible(self, scene: Scene) -> bool:
        objects = scene.objects
        blocks = scene.blocks
        for c in self.clauses:
            g = c.group(blocks)
            if not g or not c.leaf.feasible(objects, g):
                return False
        return True

    def can_show(self, objects: tuple[str, ...]) -> bool:
        """Could a scene of these objects show z? (the scene designer asks this of few z at a time)"""
        return self.feasible(Scene(objects=list(objects)))

    def sample_scene(self, rng: np.random.Generator) -> Scene:
        for _ in range(500):
            scene = random_scene(rng)
            if self.feasible(scene):
                return scene
        raise ValueError(f"no feasible scene of 3–5 objects found for {self.name!r}")

    def plans(self, state: WorldState, variants: int | None = None) -> list[list[Skill]]:
        """Distinct plans that satisfy z from ``state`` (first = the canonical one). A pure
        function of (z, the exact positions in their order, variants): kept, since the final
        answers ask it again for the same test scenes after every signal. Callers must not
        change the lists."""
        n = variants or max(c.leaf.variants for c in self.clauses)
        key = (self, n, tuple(state.positions.items()))
        return _PLANS.get_or_make(key, lambda: self._plans(state, n))

    def _plans(self, state: WorldState, n: int) -> list[list[Skill]]:
        out: list[list[Skill]] = []
        seen: set[str] = set()
        for v in range(n):
            s, steps = state, []
            for c in self.clauses:
                got = c.leaf.plan(s, c.group(s.blocks), v)
                if got is None:
                    break
                s, more = got
                steps.extend(more)
            else:
                if self.holds_f(facts(s)):
                    key = repr([st.model_dump() for st in steps])
                    if key not in seen:
                        seen.add(key)
                        out.append(steps)
        return out

    def plan(self, state: WorldState) -> list[Skill] | None:
        got = self.plans(state)
        return got[0] if got else None


def random_scene(rng: np.random.Generator) -> Scene:
    """3–5 objects, at least two blocks and one bowl; bowls match block colours by chance."""
    n = int(rng.integers(3, 6))
    n_blocks = int(rng.integers(2, n))
    matching = [True, None, False][int(rng.integers(0, 3))]
    return sample_scene(rng, n_blocks=n_blocks, n_bowls=n - n_blocks, matching=matching)


# ---- the grammar -------------------------------------------------------------------------

def _family(name: str, wording: str, leaves: dict[str | None, Leaf]) -> tuple[str, list[Behaviour]]:
    """A family of behaviours: one per parameter (None: the family has none)."""
    return name, [Behaviour(name, wording, leaf, param) for param, leaf in leaves.items()]


# Where the language's nodes are stricter or looser than the grammar's words, the leaves use the
# nodes' explicit options: flat (nothing on top) for "on the table" and "next to", lone blocks
# showing a tower / row / column / cluster / one bowl, moves checked against every neighbour.
ALL_FAMILIES: list[tuple[str, list[Behaviour]]] = [
    _family("in-same-bowl", "{s} go in the bowl of their own colour", {None: EveryBlock(InBowl(), "same")}),
    _family("in-other-bowl", "{s} go in a bowl of a different colour",
            {None: EveryBlock(InBowl(), "other", variants=3, spread_from=2)}),
    _family("in-any-bowl", "{s} go in bowls (any bowl)", {None: EveryBlock(InBowl(), "any", variants=3, spread_from=0)}),
    _family("on-table", "{s} stay flat on the table (not in bowls, not stacked)", {None: FlatDown(Flat(OnTable()))}),
    _family("next-to-same-bowl", "{s} go on the table next to the bowl of their own colour",
            {None: EveryBlock(Flat(NextTo()), "own-bowl")}),
    _family("tower", "{s} are stacked into one tower", {None: Stack(Tower(min_size=1, lone_flat=True), "any", variants=3)}),
    _family("distinct-corners", "{s} go on the table, each in a different corner of the table",
            {None: IntoCorners(Corners())}),
    _family("row", "{s} are aligned horizontally in one left-right row on the table",
            {None: LineUp(Row(min_size=1, beside_any=True), "any", variants=3)}),
    _family("column", "{s} are aligned vertically in one front-back column on the table",
            {None: LineUp(Column(min_size=1, beside_any=True), "any", variants=3)}),
    _family("cluster", "{s} are grouped together on the table, each touching another",
            {None: Gather(Cluster(min_size=1, touching=True), variants=2)}),
    # no blocks are in no bowl, and are not two towers
    _family("one-bowl", "{s} all go in one bowl together",
            {None: IntoOneBowl(OneBowl(min_size=1), variants=3, empty=(False, 1.0))}),
    _family("distinct-bowls", "{s} go in bowls, one block per bowl", {None: OnePerBowl(SeparateBowls(), variants=2)}),
    _family("two-towers", "{s} are stacked into two towers",
            {None: TwoStacks(TwoTowersAnyHeights(), variants=2, empty=(False, 1.0))}),
    _family("in-bowl", "{s} go in the {p} bowl", {c: EveryBlock(InNamedBowl(), c) for c in COLOR_NAMES}),
    # at most four blocks fit around one object
    _family("next-to-bowl", "{s} go on the table next to the {p} bowl",
            {c: EveryBlock(Flat(NextTo()), f"{c} bowl", max_group=4) for c in COLOR_NAMES}),
    _family("next-to-block", "{s} go on the table next to the {p} block",
            {c: EveryBlock(Flat(NextTo()), f"{c} block", max_group=4) for c in COLOR_NAMES}),
    _family("tower-on", "{s} are stacked into one tower on the {p} block",
            {c: Stack(TowerOnBlock(), c, variants=2) for c in COLOR_NAMES}),
    _family("region", "{s} go to the {p} of the table (not in bowls)",
            {name: IntoArea(rel, p) for name, (rel, p) in REGIONS.items()}),
]
CLASS_FAMILIES = [
    (name, members)
    for name, members in ALL_FAMILIES
    if name in {"in-same-bowl", "in-other-bowl", "in-any-bowl", "on-table", "next-to-same-bowl",
                "tower", "row", "column", "cluster", "one-bowl", "in-bowl", "region"}
]
PAIR_FAMILIES = [
    f[1][0] for f in CLASS_FAMILIES
    if f[0] in {"in-same-bowl", "in-other-bowl", "in-any-bowl", "on-table", "next-to-same-bowl",
                "tower", "row", "column", "cluster", "one-bowl"}
] + [b for name, members in ALL_FAMILIES if name == "region" for b in members if b.param in ("left half", "right half")]
STRUCTURES = 3  # all blocks / one colour class / both colour classes


def enumerate_hypotheses() -> list[Hypothesis]:
    """Every hypothesis of the grammar, with its description length in bits (not deduplicated)."""
    out: list[Hypothesis] = []
    root = math.log2(STRUCTURES)
    for _, members in ALL_FAMILIES:
        for b in members:
            bits = root + math.log2(len(ALL_FAMILIES)) + math.log2(len(members))
            out.append(Hypothesis((Clause("all", b),), bits))
    for cls in ("warm", "cool"):
        for _, members in CLASS_FAMILIES:
            for b in members:
                bits = root + 1 + math.log2(len(CLASS_FAMILIES)) + math.log2(len(members))
                out.append(Hypothesis((Clause(cls, b),), bits))
    k = len(PAIR_FAMILIES)
    for bw in PAIR_FAMILIES:
        for bc in PAIR_FAMILIES:
            if bw.key == bc.key:
                continue  # the same rule for both classes is the "all" hypothesis
            bits = root + math.log2(k) + math.log2(k - 1)
            out.append(Hypothesis((Clause("warm", bw), Clause("cool", bc)), bits))
    return out


def _bank(seed: int, others: int) -> list[tuple[Scene, list[Facts]]]:
    """Scenes with states that tell hypotheses apart.

    For every hypothesis: a scene it is feasible in (seeded), its initial layout, the final
    states of its alternative plans and of the plans of a few other feasible hypotheses.
    """
    rng = np.random.default_rng(seed)
    hyps = enumerate_hypotheses()
    bank = []
    for i, h in enumerate(hyps):
        scene = h.sample_scene(rng)
        state = WorldState(positions=layout(scene, seed + i))
        states = [facts(state)]
        feasible = [g for g in hyps if g is not h and g.feasible(scene)]
        picked = [feasible[j] for j in rng.choice(len(feasible), size=min(others, len(feasible)), replace=False)]
        plans = h.plans(state) + [p for g in picked for p in g.plans(state, variants=1)]
        for p in plans:
            end = run(state, p)
            if end is not None:
                states.append(facts(end))
        bank.append((scene, states))
    return bank


def _cache_sources() -> list[Path]:
    """Every source file the cached result depends on: the grammar, the goal language's nodes and
    recipes its leaves are (and the facts, placing helpers and node registry they are built on),
    all of world/, intentions/."""
    pkg = Path(__file__).resolve().parents[2]
    goals = [pkg / "goals" / name for name in ("__init__.py", "facts.py", "nodes.py", "selectors.py", "relations.py",
                                                "structures.py", "goal.py", "language.py", "planning.py", "recipes.py",
                                                "requested.py")]
    return [pkg / "learners" / "bayes" / "hypotheses.py", *goals, pkg / "registry.py", pkg / "memo.py",
            *sorted((pkg / "world").glob("*.py")), *sorted((pkg / "intentions").glob("*.py"))]


def _cache_file(seed: int, others: int, sources: list[Path] | None = None) -> Path:
    digest = hashlib.sha256(f"numpy {np.__version__}".encode())  # the bank is drawn with numpy's rng
    for path in sources if sources is not None else _cache_sources():
        digest.update(f"\0{path.parent.name}/{path.name}\0".encode())
        digest.update(path.read_bytes())
    root = Path(os.environ.get("ACTIVEINTENT_CACHE", Path.home() / ".cache" / "activeintent"))
    return root / f"bayes-hypotheses-{digest.hexdigest()[:16]}-{seed}-{others}.json"


def distinct_names(seed: int = 0, others: int = 6) -> list[str]:
    """Names of the hypotheses kept after merging those that behave the same on the bank.

    Two hypotheses are the same when they agree on feasibility and on ``satisfied`` for every
    bank state; of each such set the one with the shortest description is kept. The result is
    cached on disk (keyed by the source of the grammar, world/ and intentions/): it takes seconds.
    """
    path = _cache_file(seed, others)
    try:
        return list(json.loads(path.read_text()))
    except (OSError, ValueError):
        pass  # not computed yet (or unreadable): compute it
    hyps = sorted(enumerate_hypotheses(), key=lambda h: h.bits)
    bank = _bank(seed, others)
    kept: dict[bytes, str] = {}
    for h in hyps:
        sig = []
        for scene, states in bank:
            feas = h.feasible(scene)
            sig.append(feas)
            sig.extend(h.holds_f(f) if feas else False for f in states)
        kept.setdefault(np.packbits(np.array(sig, dtype=bool)).tobytes(), h.name)
    names = list(kept.values())
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps(names))
        os.replace(tmp, path)  # atomic: parallel workers never read half a file
    except OSError:
        pass  # a read-only home only costs the recomputation
    return names


@memoized(size=4, why="(seed, others): a pure function of them and of the sources (the disk cache's key)")
def hypothesis_space(seed: int = 0, others: int = 6) -> tuple[Hypothesis, ...]:
    """H: the grammar's hypotheses, deduplicated by behaviour (simplest first)."""
    keep = set(distinct_names(seed, others))
    return tuple(h for h in sorted(enumerate_hypotheses(), key=lambda h: h.bits) if h.name in keep)


def log_prior(hyps: tuple[Hypothesis, ...] | list[Hypothesis]) -> np.ndarray:
    """log P(h) ∝ -L(h)·ln 2, normalised over ``hyps``."""
    lp = -np.array([h.bits for h in hyps]) * math.log(2)
    return lp - np.logaddexp.reduce(lp)
