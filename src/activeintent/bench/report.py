"""report.md and success_vs_signals.png: every rate with its episode count and a 95 % Wilson
interval, per suite, baselines beside the methods, the protocol stated on top."""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path

import numpy as np

from activeintent.suites import suite_of

# The paper's Table 1: success judged by people, 5 trials each, 5 signals. Models per the paper's
# §4.1: the LLM was gpt-4-1106-preview, the vision-language model gpt-4-vision-preview; the
# preference method used the LLM, mllm the vision model alone, mllm-llm the vision model to
# retrieve r and the LLM to reason.
PAPER_LLM, PAPER_VLM = "gpt-4-1106-preview", "gpt-4-vision-preview"
PAPER_TABLE1 = {
    "preference": ({"align": 0.6, "stack": 0.0, "color-match": 0.6, "color-mismatch": 0.4}, PAPER_LLM),
    "mllm": ({"align": 0.4, "stack": 0.2, "color-match": 0.8, "color-mismatch": 0.4}, PAPER_VLM),
    "mllm-llm": ({"align": 0.6, "stack": 0.4, "color-match": 0.8, "color-mismatch": 0.6},
                 f"{PAPER_VLM} (r) + {PAPER_LLM} (z, y)"),
}


def our_model(method: str, settings: dict) -> str:
    """The model(s) behind one of our rows of a paper method, as the run's options chose them."""
    llm, vlm = settings.get("llm", "?"), settings.get("vlm") or settings.get("llm", "?")
    if method == "mllm":
        return str(vlm)
    if method == "mllm-llm":
        r = f"{vlm} (r)" if settings.get("retriever") == "vision" else "symbolic retriever (r)"
        return f"{r} + {llm} (z, y)"
    return str(llm)
BASELINES = ("zero-signal", "random-query", "random-query-preference")


def wilson(successes: float, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion (successes may be fractional: mean × n)."""
    if n == 0:
        return (0.0, 1.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(max(p * (1 - p) / n + z * z / (4 * n * n), 0.0)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def rate(values: list[float]) -> str:
    if not values:
        return "–"
    lo, hi = wilson(sum(values), len(values))
    return f"{np.mean(values):.2f} [{lo:.2f}, {hi:.2f}] (n={len(values)})"


def _ok(r: dict) -> bool:
    return not r.get("error") and r.get("success") is not None


def _short(intention: str) -> str:
    return intention.rsplit(":", 1)[-1] if ".py:" in intention else intention


def write_report(records: list[dict], methods: list[str], intentions: list[str], out: Path, settings: dict) -> Path:
    by = defaultdict(list)
    for r in records:
        by[(r["method"], r["intention"])].append(r)
    budget = settings.get("budget")
    lines = ["# activeintent benchmark", ""]
    lines.append(
        f"success@{budget}: after exactly {budget} signals (every answer counts, \"new scene\" included "
        f"unless the protocol says otherwise) the learner's answer acts on each episode's test scenes; an "
        "episode's success is the share of its test scenes (those where the hidden intention can be "
        "satisfied) that end satisfied. Cells: mean over episodes [95 % Wilson interval] (n = episodes). "
        "Test scenes are drawn independently of the hidden intention and are the same for every method "
        "and intention of a trial.")
    lines += ["", "Protocol: " + ", ".join(f"{k} = `{v}`" for k, v in settings.items()), ""]
    if settings.get("env") == "symbolic":
        lines += ["**Env: symbolic** — outcomes from the symbolic world model, not physics.", ""]
    suites: dict[str, list[str]] = defaultdict(list)
    for i in intentions:
        suites[suite_of(i)].append(i)
    for suite, names in suites.items():
        lines += [f"## Suite: {suite}", ""]
        lines += ["| method | " + " | ".join(_short(i) for i in names) + " | **all** | signals | new-scene answers | test scenes excluded | physics disagreements | errors | unscored |",
                  "|" + "---|" * (len(names) + 8)]
        for m in methods:
            every = [r for i in names for r in by.get((m, i), [])]
            ok = [r for r in every if _ok(r)]
            cells = [rate([r["success"] for r in by.get((m, i), []) if _ok(r)]) for i in names]
            signals = np.mean([r.get("signals_used", 0) for r in ok]) if ok else 0
            new = sum((r.get("answers") or {}).get("new_scene", 0) for r in ok)
            total = sum(sum((r.get("answers") or {}).values()) for r in ok)
            excl = np.mean([r.get("test_excluded", 0) for r in ok]) if ok else 0
            phys = [r for r in ok if r.get("physics_disagreements") is not None]
            dis = f"{sum(r['physics_disagreements'] for r in phys)} / {len(phys)} ep." if phys else "–"
            label = f"*{m}* (baseline)" if m in BASELINES else m
            errors = sum(1 for r in every if r.get("error"))  # unscored: no test scene could show the intention
            if m in PAPER_TABLE1 and ok:
                label += " [" + "/".join(sorted({str(r.get("variant") or "structured") for r in ok})) + "]"
            lines.append(f"| {label} | " + " | ".join(cells) + f" | **{rate([r['success'] for r in ok])}** | "
                         f"{signals:.1f} | {new}/{total} | {excl:.1f} | {dis} | {errors} | {len(every) - len(ok) - errors} |")
        if suite == "paper":
            cols = [i for i in names if i in PAPER_TABLE1["preference"][0]]
            lines += ["", "The paper's Table 1 (people judged success, 5 trials, 5 signals) with our rows of the "
                      "same methods beside it (success@K, mean over episodes; n = episodes):", "",
                      "| method | model | variant | " + " | ".join(cols) + " | average |", "|" + "---|" * (len(cols) + 4)]
            for m, (row, model) in PAPER_TABLE1.items():
                lines.append(f"| {m} (paper) | {model} | – | " + " | ".join(f"{row[i]:.1f}" for i in cols)
                             + f" | {np.mean(list(row.values())):.2f} |")
                ours = [r for i in cols for r in by.get((m, i), []) if _ok(r)]
                if m in methods and ours:
                    variants = "/".join(sorted({str(r.get("variant") or "structured") for r in ours}))
                    cells = [f"{np.mean(v):.2f} (n={len(v)})" if (v := [r["success"] for r in by.get((m, i), []) if _ok(r)])
                             else "–" for i in cols]
                    lines.append(f"| {m} (ours) | {our_model(m, settings)} | {variants} | " + " | ".join(cells)
                                 + f" | {np.mean([r['success'] for r in ours]):.2f} |")
        lines.append("")
    lines += ["## success@k (all suites pooled)", "", "| method | " + " | ".join(f"k={k}" for k in range((budget or 0) + 1)) + " |",
              "|" + "---|" * ((budget or 0) + 2)]
    for m in methods:
        curves = [r["success_at"] for r in records if r["method"] == m and _ok(r) and r.get("success_at")]
        cells = []
        for k in range((budget or 0) + 1):
            vals = [c[k] for c in curves if k < len(c) and c[k] is not None]
            cells.append(f"{np.mean(vals):.2f}" if vals else "–")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    lines += ["", "![success vs signals](success_vs_signals.png)", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def plot_success_vs_signals(records: list[dict], methods: list[str], budget: int, out: Path) -> Path:
    """success@k against k for each method, with 95 % Wilson bands, one panel per suite."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    suites = sorted({suite_of(r["intention"]) for r in records}) or ["paper"]
    fig, axes = plt.subplots(1, len(suites), figsize=(5.2 * len(suites), 4.0), dpi=120, squeeze=False)
    for ax, suite in zip(axes[0], suites, strict=True):
        drawn = False
        for m in methods:
            curves = [r["success_at"] for r in records
                      if r["method"] == m and _ok(r) and r.get("success_at") and suite_of(r["intention"]) == suite]
            if not curves:
                continue
            ks, mean, lo, hi = [], [], [], []
            for k in range(budget + 1):
                vals = [c[k] for c in curves if k < len(c) and c[k] is not None]
                if vals:
                    ks.append(k)
                    mean.append(np.mean(vals))
                    a, b = wilson(sum(vals), len(vals))
                    lo.append(a)
                    hi.append(b)
            style = "--" if m in BASELINES else "-"
            ax.plot(ks, mean, style, marker="o", ms=3, label=f"{m} (n={len(curves)})")
            ax.fill_between(ks, lo, hi, alpha=0.12)
            drawn = True
        ax.set_title(f"suite: {suite}")
        ax.set_xlabel("signals given (k)")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
        if drawn:
            ax.legend(loc="upper left", fontsize=7)
    axes[0][0].set_ylabel("success of the current answer (test scenes)")
    fig.tight_layout()
    path = out / "success_vs_signals.png"
    fig.savefig(path)
    plt.close(fig)
    return path
