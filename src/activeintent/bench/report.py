"""report.md (the paper's Table 1 layout, ours beside the paper's) and success_vs_rounds.png."""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path

import numpy as np

# The paper's Table 1 (gpt-4-1106-preview as LLM, gpt-4-vision-preview as MLLM; 5 trials each).
PAPER_TABLE1 = {
    "preference": {"align": 0.6, "stack": 0.0, "color-match": 0.6, "color-mismatch": 0.4},
    "mllm": {"align": 0.4, "stack": 0.2, "color-match": 0.8, "color-mismatch": 0.4},
    "mllm-llm": {"align": 0.6, "stack": 0.4, "color-match": 0.8, "color-mismatch": 0.6},
}
PAPER_MODELS = "gpt-4-1106-preview (LLM) + gpt-4-vision-preview (MLLM), human judges"


def wilson(successes: float, n: int, z: float = 1.96) -> tuple[float, float]:
    """95% Wilson score interval of a binomial proportion."""
    if n == 0:
        return (0.0, 1.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def _short(intention: str) -> str:
    return intention.rsplit(":", 1)[-1] if ".py:" in intention else intention


def summarize(records: list[dict], methods: list[str], intentions: list[str]) -> dict:
    by = defaultdict(list)
    for r in records:
        by[(r["method"], r["intention"])].append(r)
    table = {}
    for m in methods:
        row = {}
        for i in intentions:
            recs = by.get((m, i), [])
            rates = [float(r.get("success_rate", float(r.get("success", False)))) for r in recs]
            row[i] = {"n": len(recs), "rate": float(np.mean(rates)) if rates else None,
                      "ci": wilson(sum(rates), len(rates)) if rates else None}
        every = [r for i in intentions for r in by.get((m, i), [])]
        rates = [float(r.get("success_rate", float(r.get("success", False)))) for r in every]
        table[m] = {
            "cells": row,
            "avg": float(np.mean(rates)) if rates else None,
            "avg_ci": wilson(sum(rates), len(rates)) if rates else None,
            "n": len(every),
            "errors": sum(1 for r in every if r.get("error")),
            "signals": float(np.mean([r.get("signals_used", 0) for r in every])) if every else None,
            "tokens": float(np.mean([r.get("prompt_tokens", 0) + r.get("completion_tokens", 0) for r in every])) if every else None,
            "wall_s": float(np.mean([r.get("wall_s", 0.0) for r in every])) if every else None,
            "retrievers": sorted({str(r.get("retriever")) for r in every if r.get("retriever")}),
        }
    return table


def _cell(c: dict) -> str:
    if c["rate"] is None:
        return "–"
    lo, hi = c["ci"]
    return f"{c['rate']:.2f} [{lo:.2f}, {hi:.2f}]"


def write_report(records: list[dict], methods: list[str], intentions: list[str], out: Path,
                 settings: dict, extra_sections: list[str] | None = None) -> Path:
    table = summarize(records, methods, intentions)
    names = [_short(i) for i in intentions]
    lines = ["# activeintent benchmark", ""]
    lines.append("Success rate of the final execution on a fresh scene (95% Wilson interval), "
                 "per hidden intention. Every method sees the same seeds, scenes and user noise in trial t.")
    lines.append("")
    lines.append("Settings: " + ", ".join(f"{k} = `{v}`" for k, v in settings.items()))
    lines += ["", "## Ours", ""]
    head = "| method | " + " | ".join(names) + " | average | episodes | signals used | tokens / episode | wall s / episode | retriever |"
    lines += [head, "|" + "---|" * (len(names) + 7)]
    for m in methods:
        t = table[m]
        avg = "–" if t["avg"] is None else f"**{t['avg']:.2f}** [{t['avg_ci'][0]:.2f}, {t['avg_ci'][1]:.2f}]"
        err = f" ({t['errors']} errors)" if t["errors"] else ""
        lines.append(
            f"| {m} | " + " | ".join(_cell(t["cells"][i]) for i in intentions)
            + f" | {avg} | {t['n']}{err} | {t['signals'] or 0:.1f} | {t['tokens'] or 0:.0f} | {t['wall_s'] or 0:.1f} | "
            + (", ".join(t["retrievers"]) or "–") + " |"
        )
    paper_cols = [i for i in intentions if i in PAPER_TABLE1["preference"]]
    if paper_cols:
        lines += ["", f"## The paper's Table 1 (reference, not ours: {PAPER_MODELS}; 5 trials, 5 signals)", ""]
        lines += ["| method (paper) | " + " | ".join(paper_cols) + " | average |", "|" + "---|" * (len(paper_cols) + 2)]
        for m, row in PAPER_TABLE1.items():
            lines.append(f"| {m} (paper) | " + " | ".join(f"{row[i]:.1f}" for i in paper_cols)
                         + f" | {np.mean(list(row.values())):.2f} |")
    for section in extra_sections or []:
        lines += ["", section]
    lines += ["", "![success vs rounds](success_vs_rounds.png)", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def plot_success_vs_rounds(records: list[dict], methods: list[str], rounds: int, out: Path) -> Path:
    """Success of each method's current estimate (on the test scene) after each round."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=120)
    for m in methods:
        curves = []
        for r in records:
            if r["method"] != m or r.get("error"):
                continue
            c = list(r.get("per_round_success") or [])
            if not c:
                continue
            # After an early "done" the estimate no longer changes: carry the last value forward.
            curves.append(c + [c[-1]] * (rounds - len(c)))
        if not curves:
            continue
        mean = np.mean(np.array([c[:rounds] for c in curves], dtype=float), axis=0)
        ax.plot(range(1, len(mean) + 1), mean, marker="o", label=f"{m} (n={len(curves)})")
    ax.set_xlabel("signals given (round)")
    ax.set_ylabel("success of the current estimate")
    ax.set_ylim(-0.05, 1.05)
    ax.set_xticks(range(1, rounds + 1))
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("Success vs. rounds (test scene, symbolic check)")
    fig.tight_layout()
    path = out / "success_vs_rounds.png"
    fig.savefig(path)
    plt.close(fig)
    return path
