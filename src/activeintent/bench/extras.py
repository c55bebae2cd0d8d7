"""Report sections that depend on particular methods (the Bayesian learner's information floor)."""

from __future__ import annotations

import math

import numpy as np


def extra_sections(records: list[dict], methods: list[str]) -> list[str]:
    bayes = [m for m in methods if m.startswith("bayes-")]
    if not bayes:
        return []
    from activeintent.learners.bayes.hypotheses import hypothesis_space

    n = len(hypothesis_space())
    floor = math.ceil(math.log(n, 3))
    lines = ["## Signals used vs. the information floor", "",
             f"|H| = {n} hypotheses; a preference answer (A / B / can't choose) carries at most log2 3 = 1.58 bits, "
             f"so under a uniform prior identifying one hypothesis needs at least ⌈log_3 |H|⌉ = {floor} answers.", "",
             "| method | mean signals used | floor | ratio | measured bits per signal |", "|---|---|---|---|---|"]
    for m in bayes:
        recs = [r for r in records if r["method"] == m and not r.get("error")]
        if not recs:
            continue
        used = float(np.mean([r.get("signals_used", 0) for r in recs]))
        bits = [r["learner_stats"]["bits_per_signal"] for r in recs
                if (r.get("learner_stats") or {}).get("bits_per_signal") is not None]
        lines.append(f"| {m} | {used:.2f} | {floor} | {used / floor:.2f}× | "
                     + (f"{np.mean(bits):.2f}" if bits else "–") + " |")
    return ["\n".join(lines)]
