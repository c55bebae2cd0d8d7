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


# EIG learners and the baselines that share their belief but ask at random; the decision-aware
# learners and the language learners they extend.
PAIRED = (("bayes-stop", "random-query"), ("bayes-preference", "random-query-preference"),
          ("decide-stop", "lang-stop"), ("decide-preference", "lang-preference"))


def auc(curve: list[float | None]) -> float | None:
    """Area under success@k over k = 0..K, as the mean of the curve (None if a point is missing)."""
    return None if not curve or any(v is None for v in curve) else float(np.mean(curve))


def paired_difference(records: list[dict], a: str, b: str) -> dict | None:
    """Method ``a`` minus ``b`` in AUC on the same episodes (same intention and trial: same query-
    scene seeds, user noise and test scenes): mean, 95 % interval (normal approximation of the
    paired mean, n = pairs), wins, ties, losses."""
    per = {m: {(r["intention"], r["trial"]): auc(r.get("success_at") or []) for r in records
               if r["method"] == m and _ok(r)} for m in (a, b)}
    diffs = np.array([per[a][k] - per[b][k] for k in sorted(set(per[a]) & set(per[b]))
                      if per[a][k] is not None and per[b][k] is not None])
    if len(diffs) < 2:
        return None
    half = 1.96 * float(diffs.std(ddof=1)) / math.sqrt(len(diffs))
    mean = float(diffs.mean())
    return {"a": a, "b": b, "n": len(diffs), "mean": mean, "lo": mean - half, "hi": mean + half,
            "wins": int((diffs > 1e-9).sum()), "ties": int((abs(diffs) <= 1e-9).sum()), "losses": int((diffs < -1e-9).sum())}


def rate(values: list[float]) -> str:
    if not values:
        return "–"
    lo, hi = wilson(sum(values), len(values))
    return f"{np.mean(values):.2f} [{lo:.2f}, {hi:.2f}] (n={len(values)})"


def _ok(r: dict) -> bool:
    return not r.get("error") and r.get("success") is not None


def _short(intention: str) -> str:
    return intention.rsplit(":", 1)[-1] if ".py:" in intention else intention


MIN_SCORED = 5  # an episode scored on fewer test scenes than this is named in the report


def _scored_line(by: dict, methods: list[str], names: list[str]) -> str:
    """How many test scenes the suite's episodes were scored on at k = K, and which intentions
    had an episode scored on fewer than MIN_SCORED."""
    counts = {i: [r["test_scored"] for m in methods for r in by.get((m, i), [])
                  if not r.get("error") and r.get("test_scored") is not None] for i in names}
    every = [c for v in counts.values() for c in v]
    if not every:
        return "Scored test scenes at k = K: not recorded (records older than format 3)."
    few = {i: min(v) for i, v in counts.items() if v and min(v) < MIN_SCORED}
    line = (f"Scored test scenes at k = K per episode: minimum **{min(every)}**, median {int(np.median(every))} "
            f"({len(every)} episodes).")
    if few:
        line += (f" Scored on fewer than {MIN_SCORED} in some episode (the intention can be shown in few scenes of "
                 "the intention-independent test distribution): " + ", ".join(f"{_short(i)} (min {c})" for i, c in few.items()) + ".")
    else:
        line += f" Every episode was scored on at least {MIN_SCORED}."
    return line


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
        f"and intention of a trial: {settings.get('test_scenes')} scored after every signal (the curve), "
        f"{settings.get('test_pool', 0)} more at k = K (success@K is over all of them).")
    lines += ["", "Protocol: " + ", ".join(f"{k} = `{v}`" for k, v in settings.items()), ""]
    made = sorted({(p.get("commit") or "unknown")[:10] + (" (uncommitted changes)" if p.get("dirty") else "")
                   for r in records if (p := r.get("provenance"))})
    cpus = sorted({p.get("cpu") for r in records if (p := r.get("provenance")) and p.get("cpu")})
    if made:
        lines += [f"Made by commit {', '.join(made)} on {'; '.join(cpus)} (provenance of every episode: "
                  "`provenance` in results.jsonl).", ""]
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
        lines += ["", _scored_line(by, methods, names)]
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
    pairs = [d for a, b in PAIRED if a in methods and b in methods and (d := paired_difference(records, a, b))]
    if pairs:
        lines += ["", "## Paired differences (EIG against random questions; decide against lang)", "",
                  "Area under success@k (mean over k = 0..K) of each episode, minus that of the other method "
                  "on the same intention and trial; mean [95 % interval], n = pairs.", "",
                  "| method − baseline | difference in area | wins / ties / losses |", "|---|---|---|"]
        lines += [f"| {d['a']} − {d['b']} | {d['mean']:+.3f} [{d['lo']:+.3f}, {d['hi']:+.3f}] (n={d['n']}) | "
                  f"{d['wins']} / {d['ties']} / {d['losses']} |" for d in pairs]
    lines += diagnostics_section(records, methods)
    lines += ["", "![success vs signals](success_vs_signals.png)", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def answer_diagnostics(records: list[dict]) -> dict | None:
    """Pooled over episodes: answers by kind, bits each answer gave the belief (KL of posterior
    to prior, as the learner computed it), bits its query promised, the belief's P(shown)."""
    rows = [a for r in records for a in (r.get("diagnostics") or {}).get("answers", [])]
    if not rows:
        return None
    kinds: dict[str, list[dict]] = defaultdict(list)
    for a in rows:
        kinds[a["answer"]].append(a)
    promised = [a["gain_bits"] for a in rows if a.get("gain_bits") is not None]
    curves = [b for r in records if (b := (r.get("diagnostics") or {}).get("truth_bits"))]
    drops = [(b[0] - b[-1]) / (len(b) - 1) for b in curves if len(b) > 1 and b[0] is not None and b[-1] is not None]
    return {
        "truth_drop": float(np.mean(drops)) if drops else None,  # −log₂ p(true goal), per answer
        "truth_n": len(drops),
        "n": len(rows),
        "episodes": sum(bool((r.get("diagnostics") or {}).get("answers")) for r in records),
        "share": {k: len(v) / len(rows) for k, v in sorted(kinds.items())},
        "bits": float(np.mean([a["kl_bits"] for a in rows])),
        "bits_by_kind": {k: float(np.mean([a["kl_bits"] for a in v])) for k, v in sorted(kinds.items())},
        "promised": float(np.mean(promised)) if promised else None,
        "shown_mass": float(np.mean([a["shown_mass"] for a in rows])),
    }


def diagnostics_section(records: list[dict], methods: list[str]) -> list[str]:
    """Why one learner beats another: what its answers were and what they told it, per suite."""
    lines: list[str] = []
    suites = sorted({suite_of(r["intention"]) for r in records})
    for suite in suites:
        for m in methods:
            d = answer_diagnostics([r for r in records if r["method"] == m and _ok(r) and suite_of(r["intention"]) == suite])
            if d is None:
                continue
            if not lines:
                lines += ["", "## What the answers told the learner (diagnostics)", "",
                          "Pooled over the episodes of a suite. bits/answer: KL(posterior ‖ prior) of one "
                          "answer, in bits (the learner's own belief and answer model); promised: the gain the "
                          "query was chosen for (EIG or decision information, bits); P(shown): the belief's "
                          "chance, before the answer, that the scene could show its goals; truth: the mean "
                          "drop of −log₂ p(true goal) per answer (hidden goals of the language, episodes where "
                          "the learner held the goal from the start; n = episodes).", "",
                          "| suite | method | answers (episodes) | answers by kind | bits/answer | bits by kind "
                          "| promised | P(shown) | truth |", "|---|---|---|---|---|---|---|---|---|"]
            share = ", ".join(f"{k} {v:.0%}" for k, v in d["share"].items())
            by_kind = ", ".join(f"{k} {v:.2f}" for k, v in d["bits_by_kind"].items())
            promised = "–" if d["promised"] is None else f"{d['promised']:.2f}"
            truth = "–" if d["truth_drop"] is None else f"{d['truth_drop']:.2f} (n={d['truth_n']})"
            lines.append(f"| {suite} | {m} | {d['n']} ({d['episodes']}) | {share} | {d['bits']:.2f} | {by_kind} | "
                         f"{promised} | {d['shown_mass']:.2f} | {truth} |")
    return lines


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
