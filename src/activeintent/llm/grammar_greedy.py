"""Greedy decoding under a grammar, the grammar asked about the model's first choice first.

llama.cpp's sampler chain for a structured answer at temperature 0 is "grammar, then greedy":
the grammar marks every token it does not allow (all 262,144 of Gemma 3's vocabulary, each
decoded and matched, at every step), then the most likely token left is taken. The most likely
token the grammar allows is the most likely token overall whenever the grammar allows that one,
so :class:`GrammarFirstGreedy` asks the grammar about the argmax alone; when the grammar
refuses it, about the most likely few (every token whose logit reaches the SHORTLIST-th largest,
so ties at the edge are all in); and about the whole vocabulary only when it refuses all of
those. The same token at every step (ties go to the lowest id in all three, as llama.cpp's
greedy sampler takes the first maximum), a fraction of the work.
"""

from __future__ import annotations

import ctypes

import numpy as np

SHORTLIST = 1024  # tokens asked about when the grammar refuses the argmax
_TOKEN_DATA = np.dtype([("id", np.int32), ("logit", np.float32), ("p", np.float32)], align=True)


class GrammarFirstGreedy:
    """A llama-cpp-python sampler (``sample(ctx, idx)``) for temperature 0 with a grammar."""

    def __init__(self, vocab, grammar, n_vocab: int):
        import llama_cpp

        self._c = llama_cpp
        self.sampler = llama_cpp.llama_sampler_init_grammar(
            vocab, grammar._grammar.encode("utf-8"), grammar._root.encode("utf-8"))
        if not self.sampler:
            raise ValueError("llama.cpp cannot compile this grammar")
        self.n_vocab = n_vocab
        self.steps = 0
        self.fallbacks = 0  # steps at which the grammar refused the argmax
        self.whole = 0  # ... and every token of the shortlist

    def __del__(self):
        if getattr(self, "sampler", None):
            self._c.llama_sampler_free(self.sampler)
            self.sampler = None

    def _apply(self, data: np.ndarray) -> None:
        """The grammar on ``data`` (token records, in place: refused tokens get logit −inf)."""
        c = self._c
        arr = c.llama_token_data_array(
            data=data.ctypes.data_as(ctypes.POINTER(c.llama_token_data)), size=len(data), selected=-1, sorted=False)
        c.llama_sampler_apply(self.sampler, ctypes.byref(arr))

    def _shortlisted(self, logits: np.ndarray) -> int | None:
        """The most likely token the grammar allows among those whose logit reaches the
        SHORTLIST-th largest (lowest id among equals), or None when it allows none of them:
        any token outside has a smaller logit than every one inside, so it is the answer of
        the whole vocabulary whenever it is not None."""
        edge = np.partition(logits, -SHORTLIST)[-SHORTLIST]
        ids = np.flatnonzero(logits >= edge)  # ascending ids: argmax below keeps the first maximum
        some = np.zeros(len(ids), _TOKEN_DATA)
        some["id"], some["logit"] = ids, logits[ids]
        self._apply(some)
        if np.isneginf(some["logit"]).all():
            return None
        return int(some["id"][int(np.argmax(some["logit"]))])

    def sample(self, ctx, idx: int = -1) -> int:
        c = self._c
        logits = np.ctypeslib.as_array(c.llama_get_logits_ith(ctx.ctx, idx), shape=(self.n_vocab,))
        token = int(np.argmax(logits))  # the first maximum, as llama.cpp's greedy sampler
        one = np.zeros(1, _TOKEN_DATA)
        one["id"], one["logit"] = token, logits[token]
        self._apply(one)
        self.steps += 1
        if np.isneginf(one["logit"][0]):
            self.fallbacks += 1
            token = self._shortlisted(logits)
            if token is None:
                self.whole += 1
                every = np.zeros(self.n_vocab, _TOKEN_DATA)
                every["id"] = np.arange(self.n_vocab, dtype=np.int32)
                every["logit"] = logits
                self._apply(every)
                token = int(every["id"][int(np.argmax(every["logit"]))])
        c.llama_sampler_accept(self.sampler, token)
        return token
