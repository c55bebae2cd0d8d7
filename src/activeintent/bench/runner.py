"""Runs every (method, intention, trial) episode; resumable and parallel.

Trial t of every method uses the same episode seed (from the bench seed, the intention and t:
the same query scenes and user noise) and every method *and intention* of trial t the same
test scenes (from the bench seed and t only). Each finished episode is appended to
``results.jsonl`` by the single parent process (records.py), so a killed run loses at most
the episodes in flight. The folder is locked for the run (one writer); on resume every line is
checked and the untrusted ones (torn, undecodable, invalid, duplicate) are moved to
``rejected.jsonl``. Pool workers die with the parent, however it ends.
"""

from __future__ import annotations

import ctypes
import json
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import get_context
from pathlib import Path

from activeintent.bench.backends import execute_ray, worker_died
from activeintent.bench.checks import Plan
from activeintent.bench.legacy import migrated
from activeintent.bench.verify import differences
from activeintent.bench.work import (
    BenchConfig,
    WorkItem,
    bench_json,
    read_bench_config,
    run_item,
    write_bench_config,
)
from activeintent.protocol import FORMAT_VERSION
from activeintent.records import dumps
from activeintent.results import (
    Candidate,
    Rejected,
    append_rejected,
    append_result,
    hold_results_folder,
    load_results,
    rewrite_results,
    set_aside_rejected,
)
from activeintent.runner import check_spec, for_method


def run_bench(options: BenchConfig, out: Path, on_done: Callable[[dict, int, int], None] | None = None,
              on_rejected: Callable[[list[Rejected], Path], None] | None = None) -> list[dict]:
    """Run what is missing from ``out/results.jsonl``; returns all records. Every line is checked
    against the folder's plan (bench/checks.py); ``on_rejected`` hears of the lines set aside
    into ``rejected.jsonl`` (never counted, never fatal). An episode recorded more than once is
    run again once: the record equal to the re-run is kept, the others are set aside (none
    equal: all of them, and the re-run is the record)."""
    with hold_results_folder(out):
        results_path = out / "results.jsonl"
        _check_same_settings(options, out / "bench.json")
        plan_options = _planned(options, out / "bench.json")
        write_bench_config(plan_options, out / "bench.json")
        loaded = load_results(results_path, Plan(plan_options))
        if options.retry_errors:
            loaded.lines = [c for c in loaded.lines if not c.record.get("error")]
        duplicates = loaded.duplicates
        rejected_file = set_aside_rejected(results_path, loaded)
        if options.retry_errors and rejected_file is None:
            rewrite_results(results_path, loaded.raw)
        if rejected_file is not None and on_rejected:
            on_rejected(loaded.rejected, rejected_file)
        records = loaded.records
        done = {(r["method"], r["intention"], r["trial"]) for r in records}
        planned = [it.key for it in options.items()]
        todo = [it for it in options.items() if it.key not in done]
        todo += [WorkItem(method=k[0], intention=k[1], trial=k[2]) for k in duplicates if k not in planned]
        total = len(planned)
        finished = total - sum(1 for it in todo if it.key in set(planned))
        if on_done:
            on_done({}, finished, total)
        for record in _execute(todo, options, out):
            key = (record["method"], record["intention"], record["trial"])
            if key in duplicates:
                record, aside = _settle_duplicate(results_path, record, duplicates.pop(key))
                if on_rejected:
                    on_rejected(aside, results_path.with_name("rejected.jsonl"))
            else:
                append_result(results_path, record)
            records.append(record)
            finished += 1
            if on_done:
                on_done(record, finished, total)
        return records


def _settle_duplicate(path: Path, again: dict, cands: list[Candidate]) -> tuple[dict, list[Rejected]]:
    """An episode with several records in ``path``, run again: the record equal to the re-run
    (by bench-verify's comparison) stays, the others are set aside; none equal, all are, and
    the re-run's record takes their place. Set aside first, then the file rewritten at once: a
    kill in between leaves the duplicates in place, to be settled by the next resume."""
    plain = json.loads(dumps(again))  # as it would be read back
    winner = next((c for c in cands if not again.get("error") and not differences(migrated(c.record), plain)), None)
    losers = [c for c in cands if c is not winner]
    aside = [Rejected(line=c.line, kind="duplicate", text=c.raw.decode("utf-8", "backslashreplace"),
                      reason=(f"one of {len(cands)} records of {c.key[0]} / {c.key[1]} / trial {c.key[2]}: "
                              + ("another one equals the episode run again" if winner
                                 else "none equals the episode run again, whose record replaces them")))
             for c in losers]
    append_rejected(path, aside)
    lines = [line for line in path.read_bytes().split(b"\n") if line.strip()]
    for c in losers:
        lines.remove(c.raw)  # identical lines are interchangeable: any one of them goes
    if winner is None:
        lines.append(dumps({"format": FORMAT_VERSION, **again}).encode())
    rewrite_results(path, lines)
    return (winner.record if winner else again), aside


def _planned(options: BenchConfig, path: Path) -> BenchConfig:
    """The folder's plan after this resume: methods, intentions and trials may grow on resume,
    and a resume that names fewer keeps those of the folder (its records stay planned)."""
    if not path.exists():
        return options
    before = read_bench_config(path)

    def union(a: list[str], b: list[str]) -> list[str]:
        return a + [x for x in b if x not in a]

    return options.model_copy(update={"methods": union(options.methods, before.methods),
                                      "intentions": union(options.intentions, before.intentions),
                                      "intention_files": union(options.intention_files, before.intention_files),
                                      "trials": max(options.trials, before.trials)})


def _effective(options: BenchConfig | dict, methods: list[str]) -> dict:
    """What a folder's episodes are made with: the bench's seed, its spec but the learner's section,
    and each method's own settings, defaults filled in (a setting given to a benchmark goes to the
    methods that have it)."""
    if isinstance(options, dict):
        options = BenchConfig.model_validate(options)
    run = options.run.model_dump(mode="json", exclude={"learner", "plugins"})
    own = {}
    for m in methods:
        try:
            own[m] = check_spec(for_method(options.run, m)).learner.settings
        except ValueError as err:
            own[m] = f"({err})"
    return {"seed": options.seed, "run": run, "settings": own}


def _check_same_settings(options: BenchConfig, path: Path) -> None:
    """Resuming into a folder made with other settings would mix incomparable episodes."""
    if not path.exists():
        return
    before = bench_json(path)  # an older format: the values it ran with
    methods = list(dict.fromkeys(before.get("methods", []) + options.methods))
    then, now = _effective(before, methods), _effective(options, methods)
    changed = [k for k in then if then[k] != now[k]]
    if changed:
        diff = "; ".join(f"{k}: {then[k]} → {now[k]}" for k in changed)
        raise ValueError(f"{path.parent} holds results made with other settings ({diff}). "
                         "Use another --out, or the same settings to resume.")


def _execute(todo: list[WorkItem], options: BenchConfig, out: Path) -> Iterator[dict]:
    if options.backend == "ray":
        yield from execute_ray(todo, options, out)
        return
    args = (options.run, options.seed, str(out), options.keep_episodes)
    if options.jobs <= 1:
        for item in todo:
            yield run_item(item, *args)
        return
    queue = list(todo)
    while queue:
        suspects: list[WorkItem] = []
        with _pool(options.jobs) as pool:
            pending: dict[Future, WorkItem] = {}
            while (queue or pending) and not suspects:
                while queue and len(pending) < options.jobs:
                    item = queue.pop(0)
                    pending[pool.submit(run_item, item, *args)] = item
                finished, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in finished:
                    if isinstance(fut.exception(), BrokenProcessPool):
                        suspects = list(pending.values())  # a worker died: which episode killed it?
                        break
                    pending.pop(fut)
                    yield fut.result()
        # Run each episode that was in flight alone: the one that dies again is recorded as an
        # error (e.g. a native crash), the others give their results; then go on in parallel.
        for item in suspects:
            with _pool(1) as alone:
                fut = alone.submit(run_item, item, *args)
                wait([fut])
                if isinstance(fut.exception(), BrokenProcessPool):
                    yield worker_died(item, options)
                else:
                    yield fut.result()


def _pool(jobs: int) -> ProcessPoolExecutor:
    # spawn: every worker starts clean (own PyBullet client, own llama.cpp handle).
    return ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn"),
                               initializer=die_with_parent, initargs=(os.getpid(),))


PR_SET_PDEATHSIG = 1  # linux/prctl.h
PARENT_POLL_S = 1.0


def die_with_parent(parent: int) -> None:
    """Pool worker initializer. A worker whose bench is gone (kill -9) would wait for work
    forever, holding its memory (and keeping the resource tracker alive): on Linux the kernel
    kills it when the parent dies (PR_SET_PDEATHSIG); elsewhere, and as a second line, a
    watchdog thread exits when the parent changes."""
    if sys.platform.startswith("linux"):
        try:
            ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):
            pass  # the watchdog still covers it
    if os.getppid() != parent:  # the parent died before the signal was armed
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), name="parent-watchdog", daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    os._exit(1)
