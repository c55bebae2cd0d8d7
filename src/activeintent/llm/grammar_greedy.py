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


class GrammarFirstSampling(GrammarFirstGreedy):
    """A llama-cpp-python sampler for temperature > 0 with a grammar: llama.cpp's chain
    "grammar, top-k, typical, top-p, min-p, temperature, draw" with the grammar asked about the
    shortlist first.

    Only the top-k tokens the grammar allows go on past the grammar. When the shortlist (every
    token whose logit reaches the SHORTLIST-th largest) holds at least k allowed tokens, those
    are the k most likely allowed tokens of the whole vocabulary (every token outside has a
    smaller logit), so the rest of the chain sees what it would see after the grammar had been
    asked about all 262,144 tokens; else the grammar is asked about the whole vocabulary, as
    llama.cpp does. The rest of the chain is llama.cpp's own samplers with the same seed, so a
    draw is the draw llama.cpp's chain makes (ties at the k-th logit aside).
    """

    def __init__(self, vocab, grammar, n_vocab: int, *, top_k: int, typical_p: float, top_p: float, min_p: float,
                 temp: float, seed: int):
        super().__init__(vocab, grammar, n_vocab)
        c = self._c
        self.top_k = top_k
        self.chain = c.llama_sampler_chain_init(c.llama_sampler_chain_default_params())
        for sampler in (c.llama_sampler_init_top_k(top_k), c.llama_sampler_init_typical(typical_p, 1),
                        c.llama_sampler_init_top_p(top_p, 1), c.llama_sampler_init_min_p(min_p, 1),
                        c.llama_sampler_init_temp(temp), c.llama_sampler_init_dist(seed)):
            c.llama_sampler_chain_add(self.chain, sampler)

    def __del__(self):
        if getattr(self, "chain", None):
            self._c.llama_sampler_free(self.chain)
            self.chain = None
        super().__del__()

    def _candidates(self, logits: np.ndarray) -> np.ndarray:
        """The tokens the chain goes on with: the shortlist when it holds top_k allowed tokens
        (refused ones at −inf), else the whole vocabulary after the grammar."""
        self.steps += 1
        if 0 < self.top_k <= SHORTLIST // 2:
            edge = np.partition(logits, -SHORTLIST)[-SHORTLIST]
            ids = np.flatnonzero(logits >= edge)
            some = np.zeros(len(ids), _TOKEN_DATA)
            some["id"], some["logit"] = ids, logits[ids]
            self._apply(some)
            if np.count_nonzero(~np.isneginf(some["logit"])) >= self.top_k:
                return some
        self.whole += 1
        every = np.zeros(self.n_vocab, _TOKEN_DATA)
        every["id"] = np.arange(self.n_vocab, dtype=np.int32)
        every["logit"] = logits
        self._apply(every)
        return every

    def sample(self, ctx, idx: int = -1) -> int:
        c = self._c
        logits = np.ctypeslib.as_array(c.llama_get_logits_ith(ctx.ctx, idx), shape=(self.n_vocab,))
        data = self._candidates(logits)
        arr = c.llama_token_data_array(
            data=data.ctypes.data_as(ctypes.POINTER(c.llama_token_data)), size=len(data), selected=-1, sorted=False)
        c.llama_sampler_apply(self.chain, ctypes.byref(arr))
        token = int(data["id"][arr.selected])
        c.llama_sampler_accept(self.sampler, token)
        c.llama_sampler_accept(self.chain, token)
        return token
