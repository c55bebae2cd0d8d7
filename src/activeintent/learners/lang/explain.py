"""From an English sentence to the closest goals of the language by words (``hypotheses
--explain "…"``), and a summary of the language (``hypotheses --language``).

Words are not behaviour: "the red block on the blue block" and its reverse share every word.
The matcher is only a lookup — words are normalised (plurals, a few synonyms), every one-clause
goal's sentence is compared with the request by weighted word overlap, and a two-part request
("…, and …") is also matched as a pair of clauses. Whether the language can *say* an intention
is measured on its checker by ``bench/coverage.py`` (``--explain`` given an intention's name or
``path.py:NAME`` uses that).
"""

from __future__ import annotations

import math
import re
from collections import Counter

from activeintent.goals.goal import Goal, all_clauses
from activeintent.goals.nodes import NODES, nodes, speaking, spoken
from activeintent.learners.lang.learner import KEEP
from activeintent.learners.lang.space import goal_space, space_info
from activeintent.memo import memoized

MIN_SCORE = 0.45
STOP = {"the", "a", "an", "is", "are", "be", "should", "to", "of", "on", "in", "and", "it", "its", "their",
        "all", "please", "put", "place", "each", "every", "go", "table", "them", "they", "with", "by",
        "want", "i", "that", "so", "into", "one", "let", "make", "sure", "at", "from", "other"}
SYNONYMS = {
    "color": "colour", "grey": "gray", "stacked": "tower", "stack": "tower", "pile": "tower",
    "line": "row", "horizontally": "row", "horizontal": "row", "aligned": "row", "align": "row",
    "vertically": "column", "vertical": "column", "matching": "own", "match": "own", "same": "own",
    "different": "another", "mismatch": "another", "mismatched": "another", "warm": "warm",
    "cold": "cool", "top": "back", "bottom": "front", "far": "back", "near": "front", "center": "centre",
    "beside": "next", "touching": "touching", "together": "together", "separate": "per", "apart": "per",
    "rainbow": "rainbow", "stay": "stays", "untouched": "stays", "leave": "stays", "remain": "stays",
}


def words(text: str) -> list[str]:
    out = []
    for w in re.findall(r"[a-z]+", text.lower()):
        w = SYNONYMS.get(w, w)
        if len(w) > 3 and w.endswith("s") and w not in {"stays", "class", "towers"}:
            w = w[:-1]
        w = SYNONYMS.get(w, w)
        if w not in STOP:
            out.append(w)
    return out


@memoized(size=4, why="a language version: its one-clause goals and their words (the nodes registered by then)")
def _index(language: int) -> tuple[list[Goal], list[Counter], dict[str, float]]:
    with speaking(language):
        goals = [Goal((c,)) for c in all_clauses()]
    bags = [Counter(words(re.sub(r"\(.*?\)", "", g.sentence()))) for g in goals]
    df: Counter = Counter()
    for b in bags:
        df.update(set(b))
    idf = {w: math.log(len(bags) / n) + 1 for w, n in df.items()}
    return goals, bags, idf


def _sim(query: Counter, bag: Counter, idf: dict[str, float]) -> float:
    """Weighted overlap, symmetric (F1-like) so that both extra and missing words cost."""
    common = sum(idf.get(w, 3.0) for w in query if w in bag)
    q = sum(idf.get(w, 3.0) for w in query)
    b = sum(idf.get(w, 3.0) for w in bag)
    return 2 * common / (q + b) if q and b else 0.0


def word_order(query: list[str], sentence: list[str]) -> float:
    """How far the words ``query`` and ``sentence`` share come in the same order: the fraction of
    pairs of shared words (each at its first place) in the same order in both, 1.0 with fewer
    than two. It tells a relation's direction: "the blue block on the red block" shares every
    word with "Every red block is on the blue block." but not their order."""
    q = {w: i for i, w in reversed(list(enumerate(query)))}
    s = {w: i for i, w in reversed(list(enumerate(sentence)))}
    shared = sorted(set(q) & set(s), key=q.__getitem__)
    pairs = [(a, b) for i, a in enumerate(shared) for b in shared[i + 1:]]
    return sum(s[a] < s[b] for a, b in pairs) / len(pairs) if pairs else 1.0


# Words in the wrong order cost at most this much of the score: it ranks the direction of a
# relation the sentence says above its reverse (the same words), and moves no score by more.
ORDER_WEIGHT = 0.05


def _matches(text: str, n: int) -> list[tuple[float, Goal]]:
    language = spoken()
    goals, bags, idf = _index(language)
    seq = words(text)
    q = Counter(seq)
    scored = sorted(((_sim(q, b, idf) - ORDER_WEIGHT * (1 - word_order(seq, _sequence(language, i))), -g.bits, i)
                     for i, (g, b) in enumerate(zip(goals, bags, strict=True))), reverse=True)[:n]
    return [(s, goals[i]) for s, _, i in scored]


# every clause of the largest language (229,080) is asked for on every match: all kept
@memoized(size=1 << 19, why="(language version, clause index): the words of that clause's sentence")
def _sequence(language: int, i: int) -> list[str]:
    return words(re.sub(r"\(.*?\)", "", _index(language)[0][i].sentence()))


def explain(sentence: str, n: int = 5) -> dict:
    """The closest goals to ``sentence`` (one clause, or two for a two-part request)."""
    stays = "stays" in words(sentence)
    core = re.split(r"(?:everything|every other block|the rest|other blocks?)\s+(?:else\s+)?(?:stay|remain)",
                    sentence, flags=re.I)[0]
    found = [(s, Goal(g.clauses, stays)) for s, g in _matches(core, n)]
    parts = [p for p in re.split(r",?\s+and\s+|;\s*|,\s+while\s+|,\s+but\s+", core) if len(words(p)) >= 2]
    if len(parts) == 2:
        a, b = _matches(parts[0], 3), _matches(parts[1], 3)
        for sa, ga in a:
            for sb, gb in b:
                if ga.key != gb.key:
                    found.append(((sa + sb) / 2, Goal(ga.clauses + gb.clauses, stays)))
    found.sort(key=lambda x: (-x[0], x[1].bits))
    rows = [{"score": round(s, 3), "key": g.key, "bits": round(g.bits, 2), "sentence": g.sentence()}
            for s, g in found[:n]]
    ok = bool(rows) and rows[0]["score"] >= MIN_SCORE
    return {"sentence": sentence, "lexical_match": ok, "matches": rows,
            "note": ("goals whose sentences share the request's words (a lookup by words, not a test: "
                     "give an intention name or path.py:NAME to measure whether a goal does what it asks)"
                     if ok else "no goal's sentence shares the request's words; the closest ones are listed")}


def language_summary(examples: int = 12) -> dict:
    """Node types with their parameters and bits, the counts of the space, examples."""
    kinds = {}
    for kind in NODES:
        kinds[kind] = [{"key": k, "choices": len(node.params), "bits": round(node.bits(), 2),
                        "params": list(node.params[:6]) + (["…"] if len(node.params) > 6 else [])}
                       for k, node in nodes(kind).items()]
    info = space_info(0, KEEP)
    goals = goal_space(0, KEEP)
    step = max(1, len(goals) // max(examples, 1))
    return {
        "language": spoken(),
        "grammar": ["goal → clause [& clause [& clause]] [& every other block stays]",
                    "clause → quantifier selector relation | structure selector",
                    "quantifier → every | none | (exactly | at-least) (1 | 2)",
                    "structure → shape [in an order] [at a place]",
                    "bits L(z): a uniform choice at every choice point (n clauses: n bits; a later clause's blocks: "
                    "the same / the others / named anew, log2 3 bits); prior P(z) ∝ 2^-L(z) (docs/bayes.md)",
                    "node bits below: which type, then which parameter (for structures: the mean over orders and places)",
                    f"the learner starts from the {KEEP} shortest distinct goals; after each answer "
                    "neighbours of its likely goals (and with --llm a model's goals) join the belief"],
        "nodes": kinds,
        "counts": {k: v for k, v in info.items() if k not in ("keys", "distinct_bits")} | {"kept": len(info["keys"])},
        "examples": [{"key": g.key, "bits": round(g.bits, 2), "sentence": g.sentence()} for g in goals[::step]],
    }
