"""`activeintent bench-verify DIR`: re-run a sample of a results folder's episodes from its
recorded settings (``bench.json``) and compare them with the recorded lines, so published
numbers cannot drift from the code silently. Before that, every line is checked against the
folder's plan and itself (bench/checks.py, cheap): a line that does not belong, or an episode
recorded twice, fails the folder.

Whole records are compared, except what describes the run rather than the episode: tokens spent, wall time
and its split, provenance (commit, versions, CPU, date) and tracebacks. A folder written under
an older record format, or one that says in ``NOT-VERIFIED.md`` why it cannot be re-run (e.g. it
needs a model server), is refused, not reported as different.
"""

from __future__ import annotations

from pathlib import Path

from activeintent.bench.checks import Plan
from activeintent.bench.legacy import migrated
from activeintent.bench.work import WorkItem, read_bench_config, run_item
from activeintent.protocol import FORMAT_VERSION
from activeintent.results import load_results, read_results

NOT_VERIFIED = "NOT-VERIFIED.md"  # a folder's own word on why it cannot be re-run
# Tokens describe what answering cost this run: a re-run whose answers come from the response
# cache spends none (its model calls and answers are compared).
NOT_COMPARED = frozenset({"wall_s", "time_split", "provenance", "traceback", "prompt_tokens", "completion_tokens"})
# Record fields compared only when the recorded episode has them: an older record cannot differ in a
# field it never had (diagnostics, final_scene were added within format 3; a line read from the
# old shape has no retriever, variant of its own: bench/legacy.py).
COMPARED_WHEN_RECORDED = frozenset({"diagnostics", "final_scene", "retriever", "variant"})
# Fields whose meaning changed within format 3, compared when the recorded episode has the field
# that marks the new meaning: final_z / final_goal came from test scene 0 before ``final_scene``
# (the first scene that can show the intention) was recorded.
REDEFINED_IN_FORMAT_3 = {"final_z": "final_scene", "final_goal": "final_scene"}


class StaleFolder(ValueError):
    """The folder was written by code of another record format."""


def differences(recorded: dict, again: dict, prefix: str = "") -> dict[str, tuple]:
    """Fields whose values differ, nested keys joined by '.' (``NOT_COMPARED`` left out)."""
    out: dict[str, tuple] = {}
    for key in sorted(set(recorded) | set(again)):
        if not prefix and (key in NOT_COMPARED or (key in COMPARED_WHEN_RECORDED and key not in recorded)
                           or (key in REDEFINED_IN_FORMAT_3 and REDEFINED_IN_FORMAT_3[key] not in recorded)):
            continue
        a, b = recorded.get(key), again.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            out.update(differences(a, b, f"{prefix}{key}."))
        elif a != b:
            out[f"{prefix}{key}"] = (a, b)
    return out


def sample_records(records: list[dict], sample: int) -> list[dict]:
    """A deterministic spread: round-robin over methods (so every method is re-run once before
    any twice), each method's records taken from the lowest trials across intentions."""
    by_method: dict[str, list[dict]] = {}
    for r in sorted(records, key=lambda r: (r["trial"], r["intention"], r["method"])):
        by_method.setdefault(r["method"], []).append(r)
    out: list[dict] = []
    rank = 0
    while len(out) < sample and any(rank < len(v) for v in by_method.values()):
        out += [v[rank] for v in by_method.values() if rank < len(v)][:sample - len(out)]
        rank += 1
    return out


def untrusted(folder: Path) -> list:
    """Every line of the folder's results.jsonl that its plan (bench.json) or its own fields do
    not support (bench/checks.py), and every episode recorded more than once: cheap, no episode
    is run. Empty when every record belongs to the folder."""
    plan = Plan(read_bench_config(folder / "bench.json"))
    return load_results(folder / "results.jsonl", plan).set_aside_duplicates().rejected


def verify(folder: Path, sample: int, methods: list[str] | None = None) -> list[dict]:
    """Differences between recorded and re-run episodes (empty when they agree). Only records
    that pass the folder's checks (:func:`untrusted`) are sampled."""
    note = folder / NOT_VERIFIED
    if note.is_file():
        raise StaleFolder(f"{folder} cannot be verified: {note.read_text().strip().splitlines()[0].lstrip('# ')}")
    options = read_bench_config(folder / "bench.json")
    records = [r for r in read_results(folder / "results.jsonl", Plan(options)) if not r.get("error")]
    old = sorted({r.get("format") for r in records if r.get("format") != FORMAT_VERSION}, key=str)
    if old:
        raise StaleFolder(f"{folder} holds records of format {', '.join(map(str, old))}; this code writes format "
                          f"{FORMAT_VERSION} (another protocol): regenerate the folder with the command in its "
                          "report, it cannot be verified")
    if methods:
        records = [r for r in records if r["method"] in methods]
    diffs = []
    for rec in sample_records(records, sample):
        item = WorkItem(method=rec["method"], intention=rec["intention"], trial=rec["trial"])
        again = run_item(item, options.run, options.seed, str(folder), keep=False)
        changed = differences(migrated(rec), migrated(again))
        if changed:
            diffs.append({"method": item.method, "intention": item.intention, "trial": item.trial, "changed": changed})
    return diffs


def committed_folders(root: Path) -> list[Path]:
    """Every committed results folder that ``bench`` wrote: docs/results/* (the headline ones)
    and experiments/*/results/* (each experiment's)."""
    found = [*(root / "docs" / "results").glob("*/bench.json"), *(root / "experiments").glob("*/results/*/bench.json")]
    return sorted(p.parent for p in found if (p.parent / "results.jsonl").is_file())


def methods_of(folder: Path) -> list[str]:
    return sorted({r["method"] for r in read_results(folder / "results.jsonl") if not r.get("error")})
