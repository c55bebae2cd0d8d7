"""Speed of one model: load time, tokens/s for free text and for structured answers, and the
latency of a learner-sized call (~600-token prompt, ~60-token structured answer)."""

from __future__ import annotations

import statistics
import time
from typing import Any

from pydantic import BaseModel, Field

from activeintent.llm.accounting import Usage
from activeintent.llm.backend import ChatRequest
from activeintent.llm.base import ChatModel, Message
from activeintent.llm.embedded import EmbeddedBackend, EmbeddedConfig
from activeintent.llm.registry import load_model, parse_spec


class BenchGoal(BaseModel):
    """Shaped like a learner's answer: the preference z and one instruction y."""

    preference: str = Field(max_length=120)
    goal: str = Field(max_length=120)
    done: bool


_COLORS = ["red", "green", "blue", "yellow", "purple", "orange", "pink", "cyan"]


_TASK = (
    "You control a robot arm above a table. It can put a block in a bowl, on another "
    "block, next to an object, or at a named place on the table (top left, top side, top "
    "right, left side, middle, right side, bottom left, bottom side, bottom right). "
    "A person has a hidden preference for how the blocks should end up. Each round you "
    "propose two goals, the robot carries out both, and the person says which one is "
    "closer to what they want, or that they could not choose."
)


def _round_line(r: int, shift: int) -> str:
    c1, c2 = _COLORS[(r + shift) % 8], _COLORS[(r + shift + 3) % 8]
    return (
        f"Round {r + 1}: scene with the {c1} block, the {c2} block, the {c1} bowl and the "
        f"{c2} bowl. Estimated preference: blocks go into bowls of a matching colour. "
        f"Goal A: put the {c1} block in the {c1} bowl and the {c2} block in the {c2} bowl. "
        f"Goal B: stack the {c1} block on the {c2} block in the middle of the table. "
        f"The person chose goal {'A' if (r + shift) % 3 else 'B'}."
    )


def _learner_prompt(history: list[str], scene_shift: int) -> list[Message]:
    scene = ", ".join(f"the {c} block" for c in _COLORS[scene_shift % 4 : scene_shift % 4 + 4])
    user = (
        f"{_TASK}\n\nEarlier rounds:\n" + "\n".join(history) + f"\n\nThe table now holds {scene}, "
        "the red bowl and the blue bowl. Estimate the preference as one sentence that agrees "
        "with every choice so far, and give one goal for this scene. Set done to true only "
        "when you are sure."
    )
    return [Message(role="user", content=user)]


def learner_sized_messages(round_index: int) -> list[Message]:
    """A prompt of about 600 tokens in the shape of the preference learner's (task, scene,
    history of rounds), varied by ``round_index`` so no two calls are the same."""
    return _learner_prompt([_round_line(r, round_index) for r in range(6)], round_index)


def growing_history_messages(rounds: int) -> list[Message]:
    """The learner-sized prompt after ``rounds`` rounds, as an episode grows it: the prompt
    after n + 1 rounds starts with everything the prompt after n rounds had before its
    closing question (6 rounds: about 600 tokens, like :func:`learner_sized_messages`)."""
    return _learner_prompt([_round_line(r, 0) for r in range(rounds)], rounds)


def _rate(usage: Usage, run: Any) -> dict[str, float]:
    before = usage.snapshot()
    started = time.perf_counter()
    run()
    seconds = time.perf_counter() - started
    spent = usage.diff(before)
    return {
        "prompt_tokens": spent.prompt_tokens,
        "completion_tokens": spent.completion_tokens,
        "seconds": round(seconds, 4),
        "tokens_per_s": round(spent.completion_tokens / seconds, 2) if seconds > 0 else 0.0,
        "repairs": spent.repairs,
    }


def _setting_pair(spec: str, embedded: EmbeddedConfig | None, setting: str, **fixed: Any):
    """(config, backend with ``setting`` off, backend with it on) of an in-process model
    (``embedded`` or ``gguf:``), ``fixed`` in both; the two share one loaded model (these
    settings are not part of what is loaded)."""
    parsed = parse_spec(spec)
    if parsed.kind not in ("embedded", "gguf"):
        raise ValueError(f"{setting} is a setting of the in-process model, not of {spec}")
    config = embedded or EmbeddedConfig()
    path = parsed.target if parsed.kind == "gguf" else None
    off, on = (EmbeddedBackend(path, config.model_copy(update={**fixed, setting: flag})) for flag in (False, True))
    return config, off, on


def _compared(off_texts: list[str], on_texts: list[str], off_s: list[float], on_s: list[float]) -> dict[str, Any]:
    """Whether every answer is byte-identical with the setting off and on, and both latencies."""
    differ = [i for i, (a, b) in enumerate(zip(off_texts, on_texts, strict=True)) if a != b]
    return {
        "identical": not differ,
        "differing_prompts": differ,
        "off": {"latency_s": off_s, "latency_s_mean": round(statistics.fmean(off_s), 4)},
        "on": {"latency_s": on_s, "latency_s_mean": round(statistics.fmean(on_s), 4)},
    }


def run_prefix_reuse(
    spec: str = "embedded",
    *,
    embedded: EmbeddedConfig | None = None,
    prompts: int = 5,
    first_rounds: int = 6,
    max_tokens: int = 160,
) -> dict[str, Any]:
    """An in-process model (``embedded`` or ``gguf:``) answers ``prompts`` learner-sized prompts
    whose history grows by one round each, once evaluating every prompt from scratch
    (``reuse_prefix`` off) and once keeping the KV cache of the whole batches shared with the
    previous prompt (on, the default). Reports both latencies and whether every answer is
    byte-identical.
    """
    config, scratch, reuse = _setting_pair(spec, embedded, "reuse_prefix")
    schema = BenchGoal.model_json_schema()
    requests = [
        ChatRequest(messages=growing_history_messages(first_rounds + k), max_tokens=max_tokens,
                    seed=config.seed, json_schema=schema, schema_name="BenchGoal")
        for k in range(prompts)
    ]
    scratch.complete(ChatRequest(messages=learner_sized_messages(0), max_tokens=8))  # warm-up

    def series(backend: EmbeddedBackend) -> tuple[list[str], list[float], list[int]]:
        backend.llama.reset()  # both series start from an empty KV cache
        texts, seconds, tokens = [], [], []
        for request in requests:
            started = time.perf_counter()
            answer = backend.complete(request)
            seconds.append(round(time.perf_counter() - started, 4))
            texts.append(answer.text)
            tokens.append(answer.prompt_tokens)
        return texts, seconds, tokens

    off_texts, off_s, prompt_tokens = series(scratch)
    on_texts, on_s, _ = series(reuse)
    scratch.llama.reset()
    return {
        "prompts": prompts,
        "prompt_tokens": prompt_tokens,
        **_compared(off_texts, on_texts, off_s, on_s),
        # The first prompt of each series has nothing to reuse; the rest show the gain.
        "speedup_after_first": round(sum(off_s[1:]) / sum(on_s[1:]), 3) if prompts > 1 else None,
    }


def run_grammar_first(
    spec: str = "embedded",
    *,
    embedded: EmbeddedConfig | None = None,
    prompts: int = 4,
    max_tokens: int = 160,
) -> dict[str, Any]:
    """An in-process model answers ``prompts`` learner-sized structured prompts with llama.cpp's
    own grammar-then-greedy chain (``grammar_first`` off) and with GrammarFirstGreedy (on, the
    default); reports both latencies and whether every answer is byte-identical."""
    config, *pair = _setting_pair(spec, embedded, "grammar_first", reuse_prefix=False)
    backends = dict(zip((False, True), pair, strict=True))
    schema = BenchGoal.model_json_schema()
    backends[True].complete(ChatRequest(messages=learner_sized_messages(0), max_tokens=8))  # warm-up
    texts: dict[bool, list[str]] = {False: [], True: []}
    seconds: dict[bool, list[float]] = {False: [], True: []}
    for k in range(prompts):
        request = ChatRequest(messages=learner_sized_messages(k + 1), max_tokens=max_tokens, seed=config.seed,
                              json_schema=schema, schema_name="BenchGoal")
        for flag in (False, True):  # alternated, so a drift in the machine's speed hits both
            started = time.perf_counter()
            texts[flag].append(backends[flag].complete(request).text)
            seconds[flag].append(round(time.perf_counter() - started, 4))
    return {
        "prompts": prompts,
        **_compared(texts[False], texts[True], seconds[False], seconds[True]),
        "speedup": round(sum(seconds[False]) / sum(seconds[True]), 3),
    }


def run_model_bench(
    spec: str,
    *,
    base_url: str | None = None,
    embedded: EmbeddedConfig | None = None,
    repeats: int = 3,
    reuse_prompts: int = 5,
) -> dict[str, Any]:
    """Everything measured without the response cache (every call reaches the model); for an
    in-process model also ``prefix_reuse`` (:func:`run_prefix_reuse`, ``reuse_prompts``
    prompts; 0 skips it)."""
    usage = Usage()
    started = time.perf_counter()
    model: ChatModel = load_model(
        spec, base_url=base_url, cache_mode="off", usage=usage, embedded=embedded
    )
    load_s = time.perf_counter() - started
    try:
        ask = [Message(role="user", content="Describe a table with three colored blocks and two bowls.")]
        model.chat(ask, max_tokens=8)  # warm-up: first-call allocations are not throughput
        free_text = _rate(usage, lambda: model.chat(ask, max_tokens=128))
        structured = _rate(usage, lambda: model.structured(ask, BenchGoal, max_tokens=160))
        latencies, prompt_tokens, completion_tokens = [], [], []
        for i in range(repeats):
            m = _rate(usage, lambda i=i: model.structured(learner_sized_messages(i), BenchGoal,
                                                          max_tokens=160))
            latencies.append(m["seconds"])
            prompt_tokens.append(m["prompt_tokens"])
            completion_tokens.append(m["completion_tokens"])
    finally:
        model.close()
    result: dict[str, Any] = {
        "model": model.name,
        "load_s": round(load_s, 3),
        "free_text": free_text,
        "structured": structured,
        "learner_call": {
            "repeats": repeats,
            "latency_s_mean": round(statistics.fmean(latencies), 4),
            "latency_s": latencies,
            "prompt_tokens_mean": statistics.fmean(prompt_tokens),
            "completion_tokens_mean": statistics.fmean(completion_tokens),
        },
        "totals": usage.snapshot().model_dump(),
    }
    if embedded is not None and spec != "openai" and not spec.startswith("openai:"):
        result["n_threads"] = embedded.n_threads
        result["n_ctx"] = embedded.n_ctx
    if reuse_prompts > 0 and (spec == "embedded" or spec.startswith("gguf:")):
        result["prefix_reuse"] = run_prefix_reuse(spec, embedded=embedded, prompts=reuse_prompts)
        result["grammar_first"] = run_grammar_first(spec, embedded=embedded, prompts=reuse_prompts)
    return result
