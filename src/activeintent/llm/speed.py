"""Speed of one model: load time, tokens/s for free text and for structured answers, and the
latency of a learner-sized call (~600-token prompt, ~60-token structured answer)."""

from __future__ import annotations

import statistics
import time
from typing import Any

from pydantic import BaseModel, Field

from activeintent.llm.accounting import Usage
from activeintent.llm.base import ChatModel, Message
from activeintent.llm.embedded import EmbeddedConfig
from activeintent.llm.registry import load_model


class BenchGoal(BaseModel):
    """Shaped like a learner's answer: the preference z and one instruction y."""

    preference: str = Field(max_length=120)
    goal: str = Field(max_length=120)
    done: bool


_COLORS = ["red", "green", "blue", "yellow", "purple", "orange", "pink", "cyan"]


def learner_sized_messages(round_index: int) -> list[Message]:
    """A prompt of about 600 tokens in the shape of the preference learner's (task, scene,
    history of rounds), varied by ``round_index`` so no two calls are the same."""
    task = (
        "You control a robot arm above a table. It can put a block in a bowl, on another "
        "block, next to an object, or at a named place on the table (top left, top side, top "
        "right, left side, middle, right side, bottom left, bottom side, bottom right). "
        "A person has a hidden preference for how the blocks should end up. Each round you "
        "propose two goals, the robot carries out both, and the person says which one is "
        "closer to what they want, or that they could not choose."
    )
    history = []
    for r in range(6):
        c1, c2 = _COLORS[(r + round_index) % 8], _COLORS[(r + round_index + 3) % 8]
        history.append(
            f"Round {r + 1}: scene with the {c1} block, the {c2} block, the {c1} bowl and the "
            f"{c2} bowl. Estimated preference: blocks go into bowls of a matching colour. "
            f"Goal A: put the {c1} block in the {c1} bowl and the {c2} block in the {c2} bowl. "
            f"Goal B: stack the {c1} block on the {c2} block in the middle of the table. "
            f"The person chose goal {'A' if (r + round_index) % 3 else 'B'}."
        )
    scene = ", ".join(f"the {c} block" for c in _COLORS[round_index % 4 : round_index % 4 + 4])
    user = (
        f"{task}\n\nEarlier rounds:\n" + "\n".join(history) + f"\n\nThe table now holds {scene}, "
        "the red bowl and the blue bowl. Estimate the preference as one sentence that agrees "
        "with every choice so far, and give one goal for this scene. Set done to true only "
        "when you are sure."
    )
    return [Message(role="user", content=user)]


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


def run_model_bench(
    spec: str,
    *,
    base_url: str | None = None,
    embedded: EmbeddedConfig | None = None,
    repeats: int = 3,
) -> dict[str, Any]:
    """Everything measured without the response cache (every call reaches the model)."""
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
    return result
