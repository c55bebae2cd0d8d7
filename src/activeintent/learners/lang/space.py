"""The hypothesis space of the language: enumeration, behavioural de-duplication, and a
vectorised judge of thousands of goals at once.

Enumeration: every one-clause goal (with and without "every other block stays where it is")
and every unordered pair of the simplest distinct clauses. De-duplication: goals are judged on
a seeded bank of probe scenes — per scene whether the goal can be shown (static check), per
probe state whether it holds, per probe move whether the move goes against it; goals with the
same answers everywhere are one (the shortest is kept), goals that hold on no probe state are
dropped (nothing could confirm them). The ``keep`` shortest distinct goals form the space
the learner starts from (it grows while learning: proposals.py).
The list is cached on disk under ``$ACTIVEINTENT_SPACE_CACHE`` (default ``$ACTIVEINTENT_CACHE``,
then ``~/.cache/activeintent``), keyed by a hash of the sources it depends on, of the registered
node types and of the language version.
"""

from __future__ import annotations

import fcntl
import hashlib
import itertools
import json
import os
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from activeintent.goals.facts import Facts, facts
from activeintent.goals.goal import (
    QUANTS,
    Each,
    Form,
    Goal,
    all_clauses,
    parse_goal,
    structure_judge,
)
from activeintent.goals.nodes import NODES, speaking, spoken
from activeintent.goals.planner import generic_moves, plan
from activeintent.goals.prior import FittedPrior, goal_bits
from activeintent.goals.structures import Placed
from activeintent.learners.bayes.hypotheses import random_scene
from activeintent.memo import BoundedCache, memoized
from activeintent.world import WorldState, apply_skill, layout
from activeintent.world.scene import kind_of

_TOKENS = itertools.count()
Q_CODE = {"every": 0, "none": 1, "exactly": 2, "at-least": 3}


class Compiled:
    """Judges a fixed list of goals on a state in one go (numpy), memoised on the Facts."""

    def __init__(self, goals: list[Goal]):
        self.goals = goals
        index: dict[str, int] = {}
        clauses = []
        for g in goals:
            for c in g.clauses:
                if c.key not in index:
                    index[c.key] = len(clauses)
                    clauses.append(c)
        self.clauses = clauses
        n = len(clauses)
        self.E = np.full((len(goals), max((len(g.clauses) for g in goals), default=1)), n)
        for i, g in enumerate(goals):
            for k, c in enumerate(g.clauses):
                self.E[i, k] = index[c.key]
        self.valid = self.E < n
        self.n_clauses = self.valid.sum(1)
        self.stays = np.array([g.stays for g in goals], bool)
        self.each = [i for i, c in enumerate(clauses) if isinstance(c, Each)]
        self.forms = [i for i, c in enumerate(clauses) if isinstance(c, Form)]
        sels: dict[tuple[str, str], int] = {}
        rels: dict[tuple[str, str], int] = {}
        for i in self.each:
            c = clauses[i]
            sels.setdefault((c.sel, c.sp), len(sels))
            rels.setdefault((c.rel, c.rp), len(rels))
        for i in self.forms:
            sels.setdefault((clauses[i].sel, clauses[i].sp), len(sels))
        self.sels, self.rels = list(sels), list(rels)
        each = [clauses[i] for i in self.each]
        self.e_sel = np.array([sels[(c.sel, c.sp)] for c in each], int)
        self.e_rel = np.array([rels[(c.rel, c.rp)] for c in each], int)
        self.e_q = np.array([Q_CODE[c.quant.rsplit("-", 1)[0] if c.quant[-1].isdigit() else c.quant] for c in each], int)
        self.e_n = np.array([int(c.quant[-1]) if c.quant[-1].isdigit() else 0 for c in each], int)
        # conditional relations ("… if there is one"): per relation the object whose absence makes
        # its clauses hold (None for the others)
        self._rel_if = [NODES["relation"][r].refers(p) if NODES["relation"][r].vacuous_without_ref else None
                        for r, p in self.rels]
        self._has_if = any(r is not None for r in self._rel_if)
        # per relation row: its node, parameter and named object, and the earlier row with the
        # same verdicts (an "if there" relation's are its inner relation's), or its own index
        self._rel_rows = [(NODES["relation"][r], p, NODES["relation"][r].refers(p)) for r, p in self.rels]
        first: dict[tuple[str, str], int] = {}
        self._rel_copy = [first.setdefault(node.same_ok(p), j) for j, (node, p, _) in enumerate(self._rel_rows)]
        self.f_sel = [sels[(clauses[i].sel, clauses[i].sp)] for i in self.forms]
        shapes: dict[tuple[str, str], int] = {}
        for i in self.forms:
            shapes.setdefault((clauses[i].struct, clauses[i].stp), len(shapes))
        self.shapes = [(NODES["structure"][st], stp) for st, stp in shapes]
        self.f_shape = [shapes[(clauses[i].struct, clauses[i].stp)] for i in self.forms]
        # A placed shape ("a row along the back edge") is its inner shape's verdict and, with a
        # place, the group's share there: each judged once per group and state (Placed.judge).
        inners: dict[tuple[str, str], int] = {}
        places: dict[str, int] = {}
        sh_inner, sh_place = [], []
        for struct, stp in self.shapes:
            if type(struct).judge is Placed.judge:
                order, _, place = stp.partition("@")
                sh_inner.append(inners.setdefault((struct.key, order), len(inners)))
                sh_place.append(places.setdefault(place, len(places)) if place else -1)
            else:
                sh_inner.append(-1)
                sh_place.append(-1)
        self._inners = [(NODES["structure"][k], order) for k, order in inners]
        self._places = list(places)
        self._sh_inner = np.array(sh_inner, int)
        self._sh_place = np.array(sh_place, int)
        self._f_index = np.array(self.forms, int)
        self._f_sel = np.array(self.f_sel, int)
        self._f_shape = np.array(self.f_shape, int)
        self._possible: BoundedCache[tuple[str, ...], np.ndarray] = BoundedCache(4096)  # per scene's objects
        self._selected: BoundedCache[tuple, np.ndarray] = BoundedCache(4096)  # per (blocks, bowls)
        self._tag = ("lang", next(_TOKENS))  # unique per judge (an id() can be reused)

    # -- per state --

    def _matrices(self, f: Facts):
        key = self._tag + ("m",)
        got = f.memo.get(key)
        if got is not None:
            return got
        blocks = f.blocks
        bowls = tuple(f.bowls)
        objects = set(blocks) | set(bowls)
        S = self._selected.get((blocks, bowls))
        if S is None:  # who each selector picks depends on the names only: once per scene
            S = np.array([[NODES["selector"][s].pick(b, bowls, p) for b in blocks] for s, p in self.sels], bool)
            S = S.reshape(len(self.sels), len(blocks))
            S.flags.writeable = False  # shared by every state of the scene
            self._selected.put((blocks, bowls), S)
        R = np.zeros((len(self.rels), len(blocks)), bool)
        X = np.zeros_like(R)
        for j, (node, p, ref) in enumerate(self._rel_rows):
            if (src := self._rel_copy[j]) != j:
                R[j], X[j] = R[src], X[src]
                continue
            if ref is None:
                R[j] = [node.ok(f, b, p) for b in blocks]
            elif ref in objects:
                for k, b in enumerate(blocks):
                    if b == ref:
                        X[j, k] = True
                    elif node.ok(f, b, p):
                        R[j, k] = True
        Si = S.astype(np.int32)
        C = Si @ R.T.astype(np.int32)
        size = Si.sum(1)[:, None] - Si @ X.T.astype(np.int32)
        got = f.memo[key] = (S, R, X, C, size)
        return got

    def clause_eval(self, f: Facts) -> tuple[np.ndarray, np.ndarray]:
        """(holds, score) per clause, with a final sentinel (True, 0)."""
        key = self._tag + ("c",)
        got = f.memo.get(key)
        if got is not None:
            return got
        n = len(self.clauses)
        holds = np.ones(n + 1, bool)
        score = np.zeros(n + 1)
        if self.each:
            _, _, _, C, size = self._matrices(f)
            cnt = C[self.e_sel, self.e_rel]
            sz = size[self.e_sel, self.e_rel]
            q, m = self.e_q, self.e_n
            h = np.where(q == 0, cnt == sz, np.where(q == 1, cnt == 0, np.where(q == 2, cnt == m, cnt >= m)))
            szc = np.maximum(sz, 1)
            s = np.where(q == 0, cnt / szc, np.where(q == 1, 1 - cnt / szc, np.where(
                q == 2, np.clip(1 - np.abs(cnt - m) / np.maximum(szc, m), 0, 1), np.minimum(cnt, m) / np.maximum(m, 1))))
            if self._has_if:
                absent = self._absent(f)
                h = h | absent
                s = np.where(absent, 1.0, s)
            holds[self.each] = h
            score[self.each] = s
        if self.forms:
            self._judge_forms(f, holds, score)
        got = f.memo[key] = (holds, score)
        return got

    def _absent(self, f: Facts) -> np.ndarray:
        """Per Each clause: does its conditional relation name an object absent from ``f``?"""
        on = set(f.pos)
        gone = np.array([r is not None and r not in on for r in self._rel_if], bool)
        return gone[self.e_rel]

    def _form_groups(self, f: Facts) -> tuple[list[tuple[str, ...]], list[int]]:
        """The distinct groups the selectors pick in ``f`` and, per selector, its group's index."""
        key = self._tag + ("groups",)
        got = f.memo.get(key)
        if got is None:
            gid: dict[tuple[str, ...], int] = {}
            groups, sel_gid = [], []
            for row in self._matrices(f)[0].tolist():
                g = tuple(b for b, x in zip(f.blocks, row, strict=True) if x)
                if g not in gid:
                    gid[g] = len(groups)
                    groups.append(g)
                sel_gid.append(gid[g])
            got = f.memo[key] = (groups, sel_gid)
        return got

    def _form_keys(self, f: Facts) -> tuple[list[tuple[str, ...]], np.ndarray, np.ndarray]:
        """The groups of ``f``, per structure clause its group's index, and its (shape, group)
        key: clauses of the same shape whose selectors pick the same blocks share a verdict."""
        key = self._tag + ("keys",)
        got = f.memo.get(key)
        if got is None:
            groups, sel_gid = self._form_groups(f)
            gid = np.asarray(sel_gid, int)[self._f_sel]
            got = f.memo[key] = (groups, gid, self._f_shape * len(groups) + gid)
        return got

    def _judge_forms(self, f: Facts, holds: np.ndarray, score: np.ndarray) -> None:
        """Every structure clause as Form.judge, without its per-clause lookups: each (shape,
        group) judged once, a placed shape as its inner verdict per (inner shape, group) and its
        share per (place, group), combined as Placed.judge does; an empty group holds with score 1."""
        groups, _, keys = self._form_keys(f)
        n_groups = len(groups)
        uniq, inverse = np.unique(keys, return_inverse=True)
        shape, gi = np.divmod(uniq, n_groups)
        h = np.ones(len(uniq), bool)
        sc = np.ones(len(uniq))
        filled = np.array([len(g) > 0 for g in groups], bool)[gi]
        inner = self._sh_inner[shape]
        for u in np.flatnonzero(filled & (inner < 0)).tolist():
            struct, stp = self.shapes[shape[u]]
            h[u], sc[u] = structure_judge(f, struct.key, stp, groups[gi[u]])  # shared with the grown space's judge
        rows = np.flatnonzero(filled & (inner >= 0))
        if len(rows):
            pairs, at_pair = np.unique(inner[rows] * n_groups + gi[rows], return_inverse=True)
            ph = np.empty(len(pairs), bool)
            ps = np.empty(len(pairs))
            for j, k in enumerate(pairs.tolist()):
                struct, order = self._inners[k // n_groups]
                ph[j], ps[j] = struct.inner_judge(f, groups[k % n_groups], order)
            h[rows] = ph[at_pair]
            sc[rows] = ps[at_pair]
            placed = rows[self._sh_place[shape[rows]] >= 0]
            if len(placed):
                pairs, at_pair = np.unique(self._sh_place[shape[placed]] * n_groups + gi[placed], return_inverse=True)
                share = np.array([Placed.share(f, groups[k % n_groups], self._places[k // n_groups])
                                  for k in pairs.tolist()], float)[at_pair]
                h[placed] &= share == 1.0
                sc[placed] = (sc[placed] + share) / 2
        holds[self._f_index] = h[inverse]
        score[self._f_index] = sc[inverse]

    def eval(self, f: Facts) -> tuple[np.ndarray, np.ndarray]:
        """(holds, score) per goal."""
        key = self._tag + ("g",)
        got = f.memo.get(key)
        if got is None:
            h, s = self.clause_eval(f)
            holds = h[self.E].all(1)
            score = (s[self.E] * self.valid).sum(1) / self.n_clauses
            got = f.memo[key] = (holds, score)
        return got

    def clause_moved(self, fb: Facts, fa: Facts, b: str) -> tuple[np.ndarray, np.ndarray]:
        """Per clause (with a sentinel False): did moving ``b`` go against it; is ``b`` in its group."""
        key = self._tag + ("o", b)
        got = fa.memo.get(key)
        if got is not None and got[0] is fb:
            return got[1]
        n = len(self.clauses)
        off = np.zeros(n + 1, bool)
        inside = np.zeros(n + 1, bool)
        if b in fa.blocks:
            k = fa.blocks.index(b)
            if self.each:
                S, R, X, C, _ = self._matrices(fa)
                ing = S[self.e_sel, k] & ~X[self.e_rel, k]
                r = R[self.e_rel, k]
                cnt = C[self.e_sel, self.e_rel]
                q = self.e_q
                off[self.each] = ing & (((q == 0) & ~r) | ((q == 1) & r) | ((q == 2) & r & (cnt > self.e_n)))
                if self._has_if:
                    off[self.each] &= ~self._absent(fa)
                inside[self.each] = ing
            if self.forms:
                self._moved_forms(fb, fa, b, off, inside)
        fa.memo[key] = (fb, (off, inside))
        return off, inside

    def _moved_forms(self, fb: Facts, fa: Facts, b: str, off: np.ndarray, inside: np.ndarray) -> None:
        """As Form.moved_off for every structure clause whose group holds ``b``, each (shape,
        group) asked once."""
        groups, gid, keys = self._form_keys(fa)
        has_b = np.array([b in g for g in groups], bool)[gid]
        rows = np.flatnonzero(has_b)
        if not len(rows):
            return
        uniq, inverse = np.unique(keys[rows], return_inverse=True)
        went_off = np.zeros(len(uniq), bool)
        for u, k in enumerate(uniq.tolist()):
            struct, stp = self.shapes[k // len(groups)]
            went_off[u] = not struct.moved_ok(fb, fa, groups[k % len(groups)], b, stp)
        inside[self._f_index[rows]] = True
        off[self._f_index[rows]] = went_off[inverse]

    def moved_off(self, fb: Facts, fa: Facts, b: str) -> np.ndarray:
        key = self._tag + ("om", b)
        got = fa.memo.get(key)
        if got is not None and got[0] is fb:
            return got[1]
        off, inside = self.clause_moved(fb, fa, b)
        res = off[self.E].any(1) | (self.stays & ~inside[self.E].any(1))
        fa.memo[key] = (fb, res)
        return res

    # -- per scene --

    def possible(self, objects: tuple[str, ...]) -> np.ndarray:
        """Static feasibility per goal in a scene of ``objects`` (cached)."""
        key = tuple(objects)
        got = self._possible.get(key)
        if got is None:
            memo: dict = {}  # the clauses share their groups and relation checks in this scene
            c = np.array([cl.possible(key, memo) for cl in self.clauses] + [True], bool)
            got = self._possible.put(key, c[self.E].all(1))
        return got


# ---- probe bank ---------------------------------------------------------------------------


def probe_bank(seed: int = 0, n_scenes: int = 40, walks: int = 3, planned: int = 25):
    """Probe scenes with states and moves: random walks of generic moves from a layout, and
    the plans (each step) of random clauses that the scene allows."""
    rng = np.random.default_rng(seed)
    clauses = all_clauses()
    scenes, states, moves = [], [], []  # states: (scene idx, Facts); moves: (scene idx, fb, fa, block)
    for i in range(n_scenes):
        scene = random_scene(rng)
        scenes.append(tuple(scene.objects))
        s0 = WorldState(positions=layout(scene, seed * 1000 + i))
        states.append((i, facts(s0)))
        for _ in range(walks):
            s = s0
            for _ in range(3):
                options = list(generic_moves(s, facts(s), s.blocks))
                for j in rng.permutation(len(options))[:10]:
                    new, fail = apply_skill(s, options[j])
                    if fail is None:
                        states.append((i, facts(new)))
                        moves.append((i, facts(s), facts(new), options[j].block))
                        s = new
                        break
        done = 0
        for j in rng.permutation(len(clauses)):
            if done >= planned:
                break
            goal = Goal((clauses[j],))
            if not goal.possible(scenes[-1]):
                continue
            p = plan(goal, s0)
            if not p:
                continue
            done += 1
            s = s0
            for step in p:
                new, _ = apply_skill(s, step)
                states.append((i, facts(new)))
                moves.append((i, facts(s), facts(new), step.block))
                s = new
    return scenes, states, moves


# ---- enumeration and de-duplication --------------------------------------------------------


def _sources() -> list[Path]:
    pkg = Path(__file__).resolve().parents[2]
    goals = sorted((pkg / "goals").glob("*.py"))
    lang = [pkg / "learners" / "lang" / "space.py", pkg / "learners" / "bayes" / "hypotheses.py"]
    return goals + lang + sorted((pkg / "world").glob("*.py"))


def cache_path(tag: str) -> Path:
    digest = hashlib.sha256(f"numpy {np.__version__} {tag}".encode())
    for path in _sources():
        digest.update(f"\0{path.name}\0".encode())
        digest.update(path.read_bytes())
    for kind, nodes in NODES.items():  # node types registered at run time (plug-ins) count too
        for key, node in nodes.items():
            digest.update(f"\0{kind}:{key}:{type(node).__module__}.{type(node).__qualname__}:{node.params}".encode())
    default = os.environ.get("ACTIVEINTENT_CACHE", Path.home() / ".cache" / "activeintent")
    root = Path(os.environ.get("ACTIVEINTENT_SPACE_CACHE", default))  # content-addressed: may be shared
    return root / f"lang-space-{digest.hexdigest()[:16]}-{tag}.json"


def cached_json(path: Path, make: Callable[[], dict]) -> dict:
    """``make()``, kept at ``path``: read when there (and readable), else made and written
    atomically (a temporary file, then a rename: a reader never sees half a file); a cache that
    cannot be written is skipped, never fatal. Processes making the same file take turns (a
    lock beside it): the second reads what the first made (bench workers, test workers)."""
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        pass
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        lock = open(path.with_suffix(".lock"), "w")  # noqa: SIM115 - held until made
    except OSError:
        lock = None
    try:
        if lock is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                return json.loads(path.read_text())
            except (OSError, ValueError):
                pass
        value = make()
        try:
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(json.dumps(value))
            os.replace(tmp, path)
        except OSError:
            pass
        return value
    finally:
        if lock is not None:
            lock.close()


def build_space(seed: int = 0, keep: int = 3000, pair_bits: float = 13.2, n_scenes: int = 40,
                prior: FittedPrior | None = None) -> dict:
    """Enumerate, de-duplicate, keep the ``keep`` shortest (under ``prior``: the most probable);
    returns keys and counts. Pairs are formed from the simplest clauses: those up to
    ``pair_bits`` under the length prior, or as many of the most probable under ``prior``."""
    t0 = time.time()
    scenes, states, moves = probe_bank(seed, n_scenes)
    length = prior is None

    def bits(goal: Goal) -> float:
        return goal_bits(goal, prior)

    clauses = sorted(all_clauses(), key=lambda c: (c.bits if length else bits(Goal((c,))), c.key))
    simple = sum(c.bits <= pair_bits for c in clauses)  # the pair pool's size under the length prior
    comp = Compiled([Goal((c,)) for c in clauses])
    n = len(clauses)
    P = np.array([comp.possible(objs)[:n] for objs in scenes]).T  # [clause, scene]
    H = np.zeros((n, len(states)), bool)
    # The per-clause verdicts a state's memo keeps are MBs each with 10^5 clauses: dropped once
    # copied, as the bank's thousands of states would otherwise hold them all at once.
    for k, (si, f) in enumerate(states):
        H[:, k] = comp.clause_eval(f)[0][:n] & P[:, si]
        f.memo.pop(comp._tag + ("c",), None)
    Off = np.zeros((n, len(moves)), bool)
    In = np.zeros((n, len(moves)), bool)
    for k, (si, fb, fa, b) in enumerate(moves):
        off, inside = comp.clause_moved(fb, fa, b)
        Off[:, k] = off[:n] & P[:, si]
        In[:, k] = inside[:n] & P[:, si]
        fa.memo.pop(comp._tag + ("o", b), None)
    state_scene = np.array([si for si, _ in states])
    move_scene = np.array([si for si, *_ in moves])
    generated = 0
    best: dict[bytes, tuple[float, str]] = {}

    def offer(bits: np.ndarray, keys: list[str], p, h, o) -> None:
        sig = np.packbits(np.concatenate([p, h, o], axis=1), axis=1)
        for i in range(len(keys)):
            if not h[i].any():  # holds nowhere on the bank: nothing could confirm it
                continue
            k = sig[i].tobytes()
            cur = best.get(k)
            if cur is None or bits[i] < cur[0]:
                best[k] = (float(bits[i]), keys[i])

    single_bits = np.array([Goal((c,)).bits for c in clauses]) if length else None
    for stays in (False, True):
        o = Off | (stays & ~In & P[:, move_scene])
        goals = [Goal((c,), stays) for c in clauses]
        offer(single_bits + 0 if length else np.array([bits(g) for g in goals]), [g.key for g in goals], P, H, o)
        generated += len(goals)
    # pairs of the simplest behaviourally distinct clauses
    reps: dict[bytes, int] = {}
    for i in range(n):
        if (clauses[i].bits <= pair_bits if length else i < simple) and H[i].any():
            reps.setdefault(np.packbits(np.concatenate([P[i], H[i], Off[i]])).tobytes(), i)
    idx = sorted(reps.values())
    for a_pos, a in enumerate(idx):
        bs = np.array(idx[a_pos + 1:], int)
        if not len(bs):
            continue
        p = P[a] & P[bs]
        h = H[a] & H[bs]
        o = (Off[a] | Off[bs]) & p[:, move_scene]
        keys = [Goal((clauses[a], clauses[b])).key for b in bs]
        offer(np.array([bits(Goal((clauses[a], clauses[b]))) for b in bs]), keys, p, h, o)
        generated += len(bs)
    del state_scene
    distinct = sorted(best.values())
    # The space starts as the ``keep`` shortest distinct goals (most probable first under the
    # prior); longer ones join while learning (proposals.py).
    kept = [k for _, k in distinct[:keep]]
    return {"keys": kept, "distinct_bits": [round(b, 4) for b, _ in distinct], "generated": generated, "clauses": n, "distinct": len(distinct),
            "pair_clauses": len(idx), "probe_scenes": len(scenes), "probe_states": len(states),
            "probe_moves": len(moves), "seconds": round(time.time() - t0, 1)}


def space_info(seed: int = 0, keep: int = 3000, prior: FittedPrior | None = None, language: int | None = None) -> dict:
    """The built space of language ``language`` (default: the one in force), from the disk cache
    when the sources and the prior have not changed."""
    language = spoken() if language is None else language
    tag = f"{seed}-{keep}" if prior is None else f"{seed}-{keep}-{prior.tag}"
    tag += f"-v{language}"

    def make() -> dict:
        with speaking(language):
            return build_space(seed, keep, prior=prior)

    return cached_json(cache_path(tag), make)


def goal_space(seed: int = 0, keep: int = 3000, prior: FittedPrior | None = None,
               language: int | None = None) -> tuple[Goal, ...]:
    return _goal_space(seed, keep, prior, spoken() if language is None else language)


@memoized(size=4, why="(seed, keep, prior, language): a pure function of them and of the sources (the disk cache's key)")
def _goal_space(seed: int, keep: int, prior: FittedPrior | None, language: int) -> tuple[Goal, ...]:
    return tuple(parse_goal(k) for k in space_info(seed, keep, prior, language)["keys"])


__all__ = ["QUANTS", "Compiled", "build_space", "goal_space", "kind_of", "probe_bank", "space_info"]
