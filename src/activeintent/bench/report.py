"""report.md and success_vs_signals.png: every rate with its episode count and a 95 % Wilson
interval, per suite, baselines beside the methods, the protocol stated on top."""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path

import numpy as np

from activeintent.learners.base import Method
from activeintent.learners.registry import METHODS, get_method
from activeintent.results import REJECT_KINDS, rejected_counts
from activeintent.suites import is_held_out, suite_of

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


# A method's colour is its registry entry's (Method.colour), the same in every figure of every
# report; a method without one (a plug-in) gets one of the colours no built-in method uses, by a
# hash of its name.
_SPARE_COLOURS = ("#c5b0d5", "#c49c94", "#f7b6d2", "#c7c7c7", "#bcbd22", "#dbdb8d", "#17becf", "#9edae5")


def _method(name: str) -> Method | None:
    try:
        return get_method(name)
    except Exception:  # noqa: BLE001 - a plug-in method not loaded here
        return None


def is_baseline(name: str) -> bool:
    """A baseline by its registry entry's family (zero-signal, lang-zero-signal, random-query…)."""
    return getattr(_method(name), "family", None) == "baseline"


def method_colour(method: str) -> str:
    """The method's colour, the same in every figure and run (hashlib, not hash(): that is salted per process)."""
    import hashlib

    colour = (m := _method(method)) and m.colour
    if colour:
        return colour
    return _SPARE_COLOURS[int(hashlib.sha256(method.encode()).hexdigest(), 16) % len(_SPARE_COLOURS)]


def intention_label(intention: str, labels: dict[str, str] | None = None) -> str:
    """How the report names an intention: its ``name`` for a path.py:NAME one when known."""
    return (labels or {}).get(intention) or _short(intention)


def _suite_title(suite: str, names: list[str], labels: dict[str, str] | None) -> str:
    if suite == "file":
        return "your intentions (" + ", ".join(intention_label(i, labels) for i in names) + ")"
    return suite


def protocol_title(intentions: list[str], settings: dict, labels: dict[str, str] | None = None) -> str:
    """suite · user preset · K · trials · env, for titles of the report and its figures."""
    by: dict[str, list[str]] = defaultdict(list)
    for i in intentions:
        by[suite_of(i)].append(i)
    suites = ", ".join(_suite_title(s, n, labels) for s, n in by.items()) or "?"
    parts = [f"suite {suites}", f"user {settings.get('user', '?')}", f"K = {settings.get('budget', '?')} signals",
             f"{settings.get('trials', '?')} trial{'' if settings.get('trials') == 1 else 's'}",
             f"env {settings.get('env', '?')}"]
    return " · ".join(parts)


def wilson(successes: float, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion (successes may be fractional: mean × n)."""
    if n == 0:
        return (0.0, 1.0)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(max(p * (1 - p) / n + z * z / (4 * n * n), 0.0)) / denom
    return (max(0.0, centre - half), min(1.0, centre + half))


def fixed_pairs(methods: list[str]) -> list[tuple[str, str]]:
    """(method, the method its registry entry is compared with) for the methods of a bench that
    have both: EIG learners against their random-question twins, decide and hybrid against lang."""
    return [(m, c) for m in methods if (c := getattr(_method(m), "compared_with", None)) and c in methods]


def auc(curve: list[float | None]) -> float | None:
    """Area under success@k over k = 0..K, as the mean of the curve (None if a point is missing)."""
    return None if not curve or any(v is None for v in curve) else float(np.mean(curve))


def arm_row(records: list[dict], method: str) -> dict | None:
    """One method's scored episodes, as an experiment's comparison of arms shows them: n, mean
    success@K with its Wilson interval, mean area under success@k, all answers and the "new scene"
    ones (None when no episode was scored)."""
    ok = [r for r in records if r["method"] == method and r.get("success") is not None]
    if not ok:
        return None
    mean = sum(r["success"] for r in ok) / len(ok)
    lo, hi = wilson(mean * len(ok), len(ok))
    areas = [a for a in (auc(r.get("success_at") or []) for r in ok) if a is not None]
    answers = sum(sum(r.get("answers", {}).values()) for r in ok)
    new_scene = sum(r.get("answers", {}).get("new_scene", 0) for r in ok)
    return {"method": method, "n": len(ok), "success": mean, "lo": lo, "hi": hi,
            "area": sum(areas) / len(areas) if areas else None, "answers": answers, "new_scene": new_scene,
            "new_scene_share": new_scene / answers if answers else None}


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


def sign_test(wins: int, losses: int) -> float:
    """Two-sided exact sign test (ties left out): the chance of a split at least this uneven
    if either method were as likely to win."""
    n = wins + losses
    if n == 0:
        return 1.0
    tail = sum(math.comb(n, i) for i in range(min(wins, losses) + 1)) / 2**n
    return min(1.0, 2 * tail)


BOOTSTRAP_RESAMPLES = 2000


def paired_bootstrap(diffs: np.ndarray, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = 0) -> tuple[float, float]:
    """95 % percentile interval of the mean paired difference, resampling pairs (fixed seed:
    the same report from the same records)."""
    rng = np.random.default_rng(seed)
    means = diffs[rng.integers(0, len(diffs), size=(resamples, len(diffs)))].mean(axis=1)
    return float(np.percentile(means, 2.5)), float(np.percentile(means, 97.5))


def paired_comparison(records: list[dict], a: str, b: str) -> dict | None:
    """``a`` against ``b`` on the same (intention, trial): the area difference of
    :func:`paired_difference` with a sign test on it, and the success@K difference with a
    paired-bootstrap interval."""
    d = paired_difference(records, a, b)
    if d is None:
        return None
    final = {m: {(r["intention"], r["trial"]): r["success"] for r in records if r["method"] == m and _ok(r)}
             for m in (a, b)}
    diffs = np.array([final[a][k] - final[b][k] for k in sorted(set(final[a]) & set(final[b]))])
    lo, hi = paired_bootstrap(diffs)
    return {**d, "p_sign": sign_test(d["wins"], d["losses"]), "final_mean": float(diffs.mean()),
            "final_lo": lo, "final_hi": hi, "final_n": len(diffs)}


def peer_of(signal: str | None) -> str | None:
    """The field's standard peer for a signal: the first registered method of family "peer" that
    takes it (reward learning over state features); plug-in variants register after it."""
    return next((n for n in METHODS.names() if (m := _method(n)) and m.family == "peer" and m.signal == signal), None)


def _signal_of(method: str) -> str | None:
    """Its registry entry's signal; for a plug-in method not loaded here, its name's last word
    when that is the signal of a peer."""
    if (m := _method(method)) is not None:
        return m.signal
    tail = method.rsplit("-", 1)[-1]
    return tail if peer_of(tail) else None


def peer_pairs(methods: list[str]) -> list[tuple[str, str]]:
    """(learner, the reward peer of its signal) for every learner of the bench that has one."""
    out = []
    for m in methods:
        peer = peer_of(_signal_of(m))
        if peer in methods and m != peer and not is_baseline(m) and not m.startswith(peer):
            out.append((m, peer))
    return out


def best_baseline(records: list[dict], methods: list[str]) -> str | None:
    """The baseline of this bench with the highest mean success@K (the bar a learner must clear)."""
    scores = {m: float(np.mean(v)) for m in methods if is_baseline(m)
              and (v := [r["success"] for r in records if r["method"] == m and _ok(r)])}
    return max(scores, key=lambda m: (scores[m], -methods.index(m))) if scores else None


def paired_section(records: list[dict], methods: list[str]) -> list[str]:
    """The fixed pairs (EIG against random questions, decide and hybrid against lang) and every other
    method against the best baseline, on the same trials."""
    best = best_baseline(records, methods)
    pairs = fixed_pairs(methods)
    peers = [pair for pair in peer_pairs(methods) if pair not in pairs]
    pairs += peers
    if best is not None:
        pairs += [(m, best) for m in methods if not is_baseline(m) and (m, best) not in pairs]
    rows = [d for a, b in pairs if (d := paired_comparison(records, a, b))]
    if not rows:
        return []
    against = f" and every method against the best baseline here, **{best}** (highest mean success@K)" if best else ""
    extends = "decide and hybrid" if any(a.startswith("hybrid-") for a, _ in pairs) else "decide"
    peer_text = (", every learner against the reward-learning peer of its signal "
                 f"({', '.join(sorted({b for _, b in peers}))})") if peers else ""
    lines = ["", "## Paired comparisons", "",
             f"EIG against random questions, {extends} against lang{peer_text}{against}. Each episode of the method is paired "
             "with the other method's episode on the same intention and trial (same query-scene seeds, user noise "
             "and test scenes); n = pairs. Area: the mean of the episode's success@k over k = 0..K, difference "
             "with a 95 % interval from the normal approximation of the paired mean; wins / ties / losses and "
             "the two-sided sign test (ties left out) count episodes by that area. success@K: the difference at "
             f"k = K with a 95 % paired-bootstrap interval ({BOOTSTRAP_RESAMPLES} resamples of the pairs).", "",
             "| method − other | Δ area, mean [95 % interval] (n) | wins / ties / losses (area) | sign test p "
             "| Δ success@K, mean [95 % bootstrap interval] |", "|---|---|---|---|---|"]
    lines += [f"| {d['a']} − {d['b']} | {d['mean']:+.3f} [{d['lo']:+.3f}, {d['hi']:+.3f}] (n={d['n']}) | "
              f"{d['wins']} / {d['ties']} / {d['losses']} | {d['p_sign']:.3g} | "
              f"{d['final_mean']:+.3f} [{d['final_lo']:+.3f}, {d['final_hi']:+.3f}] |" for d in rows]
    return lines


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


def _scored_line(by: dict, methods: list[str], names: list[str], labels: dict[str, str] | None = None) -> str:
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
                 "the intention-independent test distribution): " + ", ".join(f"{intention_label(i, labels)} (min {c})" for i, c in few.items()) + ".")
    else:
        line += f" Every episode was scored on at least {MIN_SCORED}."
    return line


COLUMNS = ("Columns: **intentions** and **all**: success@K, mean over episodes [95 % Wilson interval] "
           "(n = scored episodes); **signals used**, **new-scene answers** and **test scenes excluded** count "
           "every episode that ran, unscored ones included: **signals used**: mean counted answers per episode; "
           "**new-scene answers**: \"new scene\" answers / all answers, summed over episodes; **test scenes "
           "excluded**: mean per episode "
           "of the test scenes scored at k = K where the hidden intention cannot be shown, so left out of "
           "success; **physics disagreements**: test scenes whose physics outcome differed from the symbolic "
           "one, summed / episodes with physics; **errors**: episodes that ended in an error; **unscored**: "
           "episodes with no feasible test scene (no success).")


def write_report(records: list[dict], methods: list[str], intentions: list[str], out: Path, settings: dict,
                 labels: dict[str, str] | None = None, oracle: dict[str, dict] | None = None) -> Path:
    """``labels``: the name of each path.py:NAME intention (the report shows names, not class names);
    ``oracle``: coverage of each intention (bench/coverage.py), shown as the oracle row."""
    by = defaultdict(list)
    for r in records:
        by[(r["method"], r["intention"])].append(r)
    budget = settings.get("budget")
    lines = [f"# activeintent benchmark — {protocol_title(intentions, settings, labels)}", ""]
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
    lines += set_aside_lines(out)
    if settings.get("env") == "symbolic":
        lines += ["**Env: symbolic** — outcomes from the symbolic world model, not physics.", ""]
    suites: dict[str, list[str]] = defaultdict(list)
    for i in intentions:
        suites[suite_of(i)].append(i)
    for suite, names in suites.items():
        lines += [f"## Suite: {_suite_title(suite, names, labels)}", ""]
        lines += ["| method | " + " | ".join(intention_label(i, labels) for i in names) + " | **all** | signals used "
                  "(mean / episode) | new-scene answers (of all answers) | test scenes excluded (mean / episode) "
                  "| physics disagreements (scenes / episodes) | errors (episodes) | unscored (episodes) |",
                  "|" + "---|" * (len(names) + 8)]
        for m in methods:
            every = [r for i in names for r in by.get((m, i), [])]
            ok = [r for r in every if _ok(r)]
            cells = [rate([r["success"] for r in by.get((m, i), []) if _ok(r)]) for i in names]
            ran = [r for r in every if not r.get("error")]  # unscored episodes asked and were answered too
            signals = np.mean([r.get("signals_used", 0) for r in ran]) if ran else 0
            new = sum((r.get("answers") or {}).get("new_scene", 0) for r in ran)
            total = sum(sum((r.get("answers") or {}).values()) for r in ran)
            excl = np.mean([r.get("test_excluded", 0) for r in ran]) if ran else 0
            phys = [r for r in ok if r.get("physics_disagreements") is not None]
            dis = f"{sum(r['physics_disagreements'] for r in phys)} / {len(phys)} ep." if phys else "–"
            label = f"*{m}* (baseline)" if is_baseline(m) else m
            errors = sum(1 for r in every if r.get("error"))  # unscored: no test scene could show the intention
            if m in PAPER_TABLE1 and ok:
                label += " [" + "/".join(sorted({str(r.get("variant") or "structured") for r in ok})) + "]"
            lines.append(f"| {label} | " + " | ".join(cells) + f" | **{rate([r['success'] for r in ok])}** | "
                         f"{signals:.1f} | {new}/{total} | {excl:.1f} | {dis} | {errors} | {len(every) - len(ok) - errors} |")
        lines += _oracle_row(oracle, suite, names, len(names))
        lines += ["", COLUMNS, "", _scored_line(by, methods, names, labels)]
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
    lines += success_at_k_table(records, methods, budget or 0)
    lines += paired_section(records, methods)
    lines += diagnostics_section(records, methods)
    lines += ["", "![success vs signals](success_vs_signals.png)", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines))
    return path


def set_aside_lines(out: Path) -> list[str]:
    """How many lines of results.jsonl were set aside into rejected.jsonl, and why (none: nothing)."""
    counts = rejected_counts(out)
    if not counts:
        return []
    why = "; ".join(f"{n} {REJECT_KINDS.get(kind, 'set aside by older code')}" for kind, n in sorted(counts.items()))
    return [f"**Set aside:** {sum(counts.values())} line(s) of results.jsonl were not trusted and are not counted "
            f"(`rejected.jsonl`, each with its reason): {why}.", ""]


def _oracle_row(oracle: dict[str, dict] | None, suite: str, names: list[str], width: int) -> list[str]:
    """The ceiling of every learner of the goal language: the best goal's plan success per
    intention (held-out suites: the mean only, their rows are read only after a freeze)."""
    if oracle is None:
        return ["| *oracle* (best goal of the goal language) | " + " | ".join("–" for _ in names)
                + " | not measured (`bench --no-oracle`) | | | | | | |"]

    got = [oracle[i]["success"] for i in names if i in oracle]
    n = oracle[names[0]]["test_scenes"] if names and names[0] in oracle else 0
    cells = ["held out" if is_held_out(suite) else (f"{oracle[i]['success']:.2f}" if i in oracle else "–")
             for i in names]
    mean = f"**{np.mean(got):.2f}** (mean of {len(got)}; plan success on {n} scenes each)" if got else "–"
    return ["| *oracle* (best goal of the goal language: the ceiling of lang-* / decide-*) | " + " | ".join(cells)
            + f" | {mean} | | | | | | |"]


def success_at_k_table(records: list[dict], methods: list[str], budget: int) -> list[str]:
    """success@k after every k, all suites pooled: mean [95 % Wilson interval], n = episodes."""
    lines = ["## success@k (all suites pooled)", "",
             "success of the learner's answer after k signals on the curve's test scenes (k = K: the whole pool), "
             "mean over episodes [95 % Wilson interval]; n = episodes with a curve.", "",
             "| method | n | " + " | ".join(f"k={k}" for k in range(budget + 1)) + " |", "|" + "---|" * (budget + 3)]
    for m in methods:
        curves = [r["success_at"] for r in records if r["method"] == m and _ok(r) and r.get("success_at")]
        cells = []
        for k in range(budget + 1):
            vals = [c[k] for c in curves if k < len(c) and c[k] is not None]
            if vals:
                lo, hi = wilson(sum(vals), len(vals))
                cells.append(f"{np.mean(vals):.2f} [{lo:.2f}, {hi:.2f}]")
            else:
                cells.append("–")
        lines.append(f"| {m} | {len(curves)} | " + " | ".join(cells) + " |")
    return lines


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


PANEL_METHODS = 4  # more methods than this in one panel: small multiples


def panel_groups(methods: list[str]) -> list[list[str]]:
    """Methods per panel, at most PANEL_METHODS each: the baselines in every panel (the bar each
    learner is read against), the other methods split over as few panels as needed."""
    if len(methods) <= PANEL_METHODS:
        return [list(methods)]
    base = [m for m in methods if is_baseline(m)]
    rest = [m for m in methods if not is_baseline(m)]
    room = PANEL_METHODS - len(base)
    if room < 1 or not rest:  # too many baselines to repeat: plain chunks
        return [methods[i:i + PANEL_METHODS] for i in range(0, len(methods), PANEL_METHODS)]
    return [rest[i:i + room] + base for i in range(0, len(rest), room)]


def _curve_band(curves: list[list], budget: int) -> tuple[list[int], list[float], list[float], list[float]]:
    ks, mean, lo, hi = [], [], [], []
    for k in range(budget + 1):
        vals = [c[k] for c in curves if k < len(c) and c[k] is not None]
        if vals:
            a, b = wilson(sum(vals), len(vals))
            ks.append(k)
            mean.append(float(np.mean(vals)))
            lo.append(a)
            hi.append(b)
    return ks, mean, lo, hi


def plot_success_vs_signals(records: list[dict], methods: list[str], budget: int, out: Path,
                            labels: dict[str, str] | None = None, settings: dict | None = None) -> Path:
    """success@k against k for each method with its 95 % Wilson band: a row per suite, small
    multiples when more than PANEL_METHODS methods would share a panel; every method has its
    :func:`method_colour`, the protocol is in the title."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator

    def curves_of(m: str, suite: str) -> list[list]:
        return [r["success_at"] for r in records
                if r["method"] == m and _ok(r) and r.get("success_at") and suite_of(r["intention"]) == suite]

    by_suite: dict[str, list[str]] = defaultdict(list)
    for r in records:
        if r["intention"] not in by_suite[suite_of(r["intention"])]:
            by_suite[suite_of(r["intention"])].append(r["intention"])
    # a suite none of whose episodes gave a curve would be an empty panel: left out
    suites = [s for s in sorted(by_suite) if any(curves_of(m, s) for m in methods)]
    groups = panel_groups(methods)
    rows = [(s, g) for s in suites for g in groups if any(curves_of(m, s) for m in g)] or [("paper", methods)]
    ncols = min(len(rows), 3)
    nrows = math.ceil(len(rows) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 4.0 * nrows + 0.6), dpi=120, squeeze=False,
                             sharey=True)
    flat = [ax for row in axes for ax in row]
    for ax, (suite, group) in zip(flat, rows, strict=False):
        for m in group:
            curves = curves_of(m, suite)
            if not curves:
                continue
            ks, mean, lo, hi = _curve_band(curves, budget)
            colour = method_colour(m)
            ax.plot(ks, mean, "--" if is_baseline(m) else "-", marker="o", ms=3, color=colour,
                    label=f"{m} (n={len(curves)})")
            ax.fill_between(ks, lo, hi, color=colour, alpha=0.12, linewidth=0)
        handles, names = ax.get_legend_handles_labels()
        handles.append(Patch(color="grey", alpha=0.25, linewidth=0))
        names.append("band: 95 % Wilson interval")
        ax.legend(handles, names, loc="upper left", fontsize=7)
        part = f" · panel {groups.index(group) + 1} of {len(groups)}" if len(groups) > 1 else ""
        ax.set_title(f"suite: {_suite_title(suite, by_suite.get(suite, []), labels)}{part}", fontsize=10)
        ax.set_xlabel("signals given (k)")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    for ax in flat[len(rows):]:
        ax.set_visible(False)
    for row in axes:
        row[0].set_ylabel("success of the current answer (test scenes)")
    intentions = [i for s in suites for i in by_suite[s]]
    title = "success@k after k signals"
    if settings:  # the protocol split over lines that fit the figure's width
        import textwrap

        title += "\n" + "\n".join(textwrap.wrap(protocol_title(intentions, settings, labels), 60 * ncols))
    fig.suptitle(title, fontsize=9)
    fig.text(0.5, 0.005, "lines: mean over episodes (dashed: baselines); bands: 95 % Wilson interval; "
             "n = episodes", ha="center", fontsize=7)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    path = out / "success_vs_signals.png"
    fig.savefig(path)
    plt.close(fig)
    return path
