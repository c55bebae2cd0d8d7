"""Ablation: a naturalness term from a language model in the prior of ``lang-<signal>``.

    bin/activeintent bench --plugin experiments/naturalness/naturalness.py \\
        --methods lang-stop,lang-natural-stop,lang-preference,lang-natural-preference --suite dev ...

The length prior P(z) ∝ 2^(−L(z)) counts the choices of z's expression in the grammar; it does
not know which of two equally long goals a person would more plausibly ask for. This variant adds
how surprising z's sentence is to a language model (the embedded Gemma 3 270M, or any GGUF):

    log₂ P(z) = −L(z) − λ·(N(z) − N̄) + const,   N(z) = −log₂ p_LM(sentence(z) | request frame)

with N̄ the mean of N over the starting space, so the term moves mass among goals and adds none on
average. Goals that join while learning (neighbours, model proposals) get N(z) = N̄: scoring a
sentence takes ~0.3 s, and hundreds join per answer — the stated approximation of this ablation.

λ: ``lang-natural-*`` gives both descriptions the same spread over the starting space,
λ = sd(L) / sd(N) (the model's bits are mostly the sentence's length, ~4 bits per token, so
their spread is ~20 times the grammar's); ``lang-natural-strong-*`` uses λ = 0.25, where the
model's term outweighs the grammar's. The sentence bits are computed once per model file and
cached on disk (``~/.cache/activeintent``).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import numpy as np

from activeintent.learners.bayes.belief import Belief
from activeintent.learners.lang.hypotheses import lang_space
from activeintent.learners.lang.learner import KEEP, LangConfig, LangLearner, LangPriorSettings
from activeintent.learners.registry import METHODS, LearnerContext, Method

FRAME = 'A person asked a robot arm to arrange the blocks and bowls on a table. They said: "'
END = '"'
WEIGHTS: dict[str, float | None] = {"natural": None, "natural-strong": 0.25}  # λ; None: sd(L) / sd(N)


# N of the starting space's sentences under the packaged model, as this file computes them: the
# bench reads them from here, so its episodes do not depend on a machine's floating point (and
# a fresh machine does not spend ~15 minutes scoring 3,000 sentences before its first episode).
TABLE = Path(__file__).with_name("naturalness_bits.json")


def _digest(model: Path) -> str:
    return hashlib.sha256(f"{model.name}\0{model.stat().st_size}\0{FRAME}\0{END}".encode()).hexdigest()[:16]


def _cache_path(model: Path) -> Path:
    root = Path(os.environ.get("ACTIVEINTENT_CACHE", Path.home() / ".cache" / "activeintent"))
    return root / f"naturalness-{_digest(model)}.json"


def _table(model: Path) -> dict[str, float]:
    """The committed N values when they were computed with this model and frame, else none."""
    try:
        table = json.loads(TABLE.read_text())
    except (OSError, ValueError):
        return {}
    return table["bits"] if table.get("digest") == _digest(model) else {}


def sentence_bits(sentences: list[str], model: Path | None = None, threads: int = 1) -> np.ndarray:
    """N(s) = −log₂ p_LM(s + END | FRAME) for each sentence, from the disk cache where known."""
    from llama_cpp import Llama

    from activeintent.llm.embedded import default_gguf

    model = Path(model or default_gguf())
    path = _cache_path(model)
    try:
        known: dict[str, float] = json.loads(path.read_text())
    except (OSError, ValueError):
        known = {}
    known.update(_table(model))
    todo = [s for s in dict.fromkeys(sentences) if s not in known]
    if todo:
        llm = Llama(model_path=str(model), n_ctx=512, n_threads=threads, n_threads_batch=threads,
                    logits_all=True, verbose=False)
        frame = llm.tokenize(FRAME.encode(), add_bos=True)
        llm.eval(frame)
        for k, s in enumerate(todo):
            tokens = llm.tokenize((FRAME + s + END).encode(), add_bos=True)
            if tokens[:len(frame)] != frame:  # the frame's last token merged with the sentence's first
                raise ValueError(f"the frame does not tokenise apart from {s!r}")
            llm.n_tokens = len(frame)  # keep the frame's KV cache, evaluate only the sentence
            llm.eval(tokens[len(frame):])
            logits = np.asarray(llm.scores[len(frame) - 1:len(tokens) - 1], dtype=np.float64)
            logp = logits - np.logaddexp.reduce(logits, axis=1, keepdims=True)
            known[s] = float(-logp[np.arange(len(logits)), tokens[len(frame):]].sum() / math.log(2))
            if k % 200 == 199 or k == len(todo) - 1:
                path.parent.mkdir(parents=True, exist_ok=True)
                tmp = path.with_suffix(f".{os.getpid()}.tmp")
                tmp.write_text(json.dumps(known))
                os.replace(tmp, path)
    return np.array([known[s] for s in sentences])


def add_naturalness(belief: Belief, n_bits: np.ndarray, weight: float | None) -> float:
    """Multiply the prior of the first ``len(n_bits)`` z (the starting space) by 2^(−λ(N − N̄));
    the belief must not have seen an answer yet. Returns λ."""
    if belief.log_evidence != 0.0:
        raise ValueError("the naturalness term is part of the prior: add it before any answer")
    if weight is None:
        lengths = np.array([h.bits for h in belief.hyps[:len(n_bits)]])
        weight = float(lengths.std() / n_bits.std())
    raw = belief.log_w + belief.log_norm  # log of the unnormalised prior, −L(z) ln 2
    raw[:len(n_bits)] -= weight * (n_bits - n_bits.mean()) * math.log(2)
    belief.log_norm = float(np.logaddexp.reduce(raw))
    belief.log_w = raw - belief.log_norm
    return weight


def natural_learner(signal: str, weight: float | None, ctx: LearnerContext, name: str) -> LangLearner:
    learner = LangLearner(signal, rng=ctx.learner_seed, llm=ctx.llm, config=LangConfig(**ctx.settings.model_dump()))
    learner.name = name
    start = [g for sp in learner.base for g in sp.goals]  # the learner's own starting space, in order
    add_naturalness(learner.belief, sentence_bits([g.sentence() for g in start]), weight)
    return learner


def _method(variant: str, signal: str) -> Method:
    weight = WEIGHTS[variant]
    name = f"lang-{variant}-{signal}"
    return Method(signal, False, lambda ctx: natural_learner(signal, weight, ctx, name),
                  f"ablation: lang-{signal} with a language model's naturalness in the prior "
                  f"(λ = {'sd(L) / sd(N)' if weight is None else weight})", goal_language=True,
                  settings=LangPriorSettings)


for _variant in WEIGHTS:
    for _signal in ("stop", "preference"):
        METHODS.register(f"lang-{_variant}-{_signal}", lambda v=_variant, s=_signal: _method(v, s))


if __name__ == "__main__":  # python experiments/naturalness/naturalness.py [--table]: fill the cache (and the table)
    import sys

    from activeintent.llm.embedded import default_gguf

    goals = lang_space(0, KEEP).goals
    bits = sentence_bits([g.sentence() for g in goals])
    if "--table" in sys.argv:
        TABLE.write_text(json.dumps({"digest": _digest(default_gguf()), "frame": FRAME, "end": END,
                                     "bits": {g.sentence(): float(b) for g, b in zip(goals, bits, strict=True)}},
                                    indent=0) + "\n")
    lengths = np.array([g.bits for g in goals])
    print(f"{len(goals)} goals: N mean {bits.mean():.1f} bits, sd {bits.std():.1f}; "
          f"corr(N, L) = {np.corrcoef(bits, lengths)[0, 1]:.2f}")
