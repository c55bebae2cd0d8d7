"""Runs every (method, intention, trial) episode; resumable and parallel.

Trial t of every method uses the same episode seed (derived from the bench seed, the
intention and t), hence the same scenes, layouts and user noise: methods are compared on
identical work. Each finished episode is appended to ``results.jsonl`` as one line, flushed
and fsynced by the single parent process, so a killed run loses at most the episodes in
flight; a torn last line is dropped on resume.
"""

from __future__ import annotations

import hashlib
import json
import os
import traceback
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import get_context
from pathlib import Path

from pydantic import BaseModel, Field

from activeintent.intentions.registry import PAPER_INTENTIONS
from activeintent.runner import RunOptions


class WorkItem(BaseModel):
    method: str
    intention: str  # name, or path.py:NAME for a user-defined intention
    trial: int

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.method, self.intention, self.trial)

    @property
    def slug(self) -> str:
        name = self.intention.replace("/", "_").replace(":", "_").replace(".py", "")
        return f"{self.method}/{name}/trial{self.trial}"


class BenchOptions(BaseModel):
    methods: list[str]
    intentions: list[str] = Field(default_factory=lambda: list(PAPER_INTENTIONS))
    intention_files: list[str] = Field(default_factory=list)
    trials: int = 5
    seed: int = 0
    jobs: int = 1
    retry_errors: bool = False
    run: RunOptions = Field(default_factory=RunOptions)  # model, executor, user… shared by all episodes

    def items(self) -> list[WorkItem]:
        names = list(self.intentions) + list(self.intention_files)
        return [WorkItem(method=m, intention=i, trial=t) for t in range(self.trials) for i in names for m in self.methods]


def episode_seed(bench_seed: int, intention: str, trial: int) -> int:
    """Same for every method: a stable hash (not Python's salted hash) of seed, intention, trial."""
    digest = hashlib.sha256(f"{bench_seed}|{intention}|{trial}".encode()).digest()
    return int.from_bytes(digest[:4], "little")


def read_results(path: Path) -> list[dict]:
    """Valid records of ``results.jsonl``; a torn or corrupt line is dropped (and the file rewritten)."""
    if not path.exists():
        return []
    good, bad = [], 0
    for line in path.read_text().splitlines():
        try:
            rec = json.loads(line)
            if isinstance(rec, dict) and {"method", "intention", "trial"} <= rec.keys():
                good.append(rec)
                continue
        except json.JSONDecodeError:
            pass
        bad += int(bool(line.strip()))
    if bad:
        tmp = path.with_suffix(".jsonl.tmp")
        tmp.write_text("".join(json.dumps(r) + "\n" for r in good))
        os.replace(tmp, path)
    return good


def append_result(path: Path, record: dict) -> None:
    line = json.dumps(record) + "\n"
    with path.open("a") as f:
        f.write(line)
        f.flush()
        os.fsync(f.fileno())


def run_item(item: WorkItem, options: RunOptions, bench_seed: int, out: str) -> dict:
    """One episode in a worker process (own simulator client, own model handles)."""
    user_defined = ".py:" in item.intention
    run = options.model_copy(update={
        "method": item.method,
        "intention": None if user_defined else item.intention,
        "intention_file": item.intention if user_defined else None,
        "seed": episode_seed(bench_seed, item.intention, item.trial),
        "track_progress": True,
    })
    base = {"method": item.method, "intention": item.intention, "trial": item.trial, "seed": run.seed,
            "user": run.user.model_dump(mode="json")}
    try:
        from activeintent.runner import build_episode

        episode = build_episode(run, Path(out) / "episodes" / item.slug)
        try:
            result = episode.run()
        finally:
            episode.env.close()
        return {**result.model_dump(mode="json"), **base}
    except Exception as err:  # noqa: BLE001 - recorded, never crashes the benchmark
        return {**base, "success": False, "success_rate": 0.0, "error": f"{type(err).__name__}: {err}",
                "traceback": traceback.format_exc(limit=8)}


def run_bench(
    options: BenchOptions,
    out: Path,
    on_done: Callable[[dict, int, int], None] | None = None,
) -> list[dict]:
    """Run what is missing from ``out/results.jsonl``; returns all records."""
    out.mkdir(parents=True, exist_ok=True)
    results_path = out / "results.jsonl"
    _check_same_settings(options, out / "bench.json")
    (out / "bench.json").write_text(options.model_dump_json(indent=2))
    records = read_results(results_path)
    if options.retry_errors:
        kept = [r for r in records if not r.get("error")]
        if len(kept) != len(records):
            results_path.write_text("".join(json.dumps(r) + "\n" for r in kept))
        records = kept
    done = {(r["method"], r["intention"], r["trial"]) for r in records}
    todo = [it for it in options.items() if it.key not in done]
    total = len(options.items())
    finished = total - len(todo)
    if on_done:
        on_done({}, finished, total)
    for record in _execute(todo, options.run, options.seed, out, options.jobs):
        append_result(results_path, record)
        records.append(record)
        finished += 1
        if on_done:
            on_done(record, finished, total)
    return records


# Options that change what an episode does; methods, intentions and trials may grow on resume.
_SETTINGS = ("seed", "run")


def _check_same_settings(options: BenchOptions, path: Path) -> None:
    """Resuming into a folder made with other settings would mix incomparable episodes."""
    if not path.exists():
        return
    before = json.loads(path.read_text())
    now = json.loads(options.model_dump_json())
    changed = [k for k in _SETTINGS if before.get(k) != now.get(k)]
    if changed:
        diff = "; ".join(f"{k}: {before.get(k)} → {now.get(k)}" for k in changed)
        raise ValueError(
            f"{path.parent} holds results made with other settings ({diff}). "
            "Use another --out, or the same settings to resume."
        )


def _execute(todo: list[WorkItem], run: RunOptions, seed: int, out: Path, jobs: int) -> Iterator[dict]:
    if jobs <= 1:
        for item in todo:
            yield run_item(item, run, seed, str(out))
        return
    queue = list(todo)
    while queue:
        suspects: list[WorkItem] = []
        with _pool(jobs) as pool:
            pending: dict[Future, WorkItem] = {}
            while (queue or pending) and not suspects:
                while queue and len(pending) < jobs:
                    item = queue.pop(0)
                    pending[pool.submit(run_item, item, run, seed, str(out))] = item
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
                fut = alone.submit(run_item, item, run, seed, str(out))
                wait([fut])
                if isinstance(fut.exception(), BrokenProcessPool):
                    yield {"method": item.method, "intention": item.intention, "trial": item.trial,
                           "success": False, "success_rate": 0.0, "error": "worker process died"}
                else:
                    yield fut.result()


def _pool(jobs: int) -> ProcessPoolExecutor:
    # spawn: every worker starts clean (own PyBullet client, own llama.cpp handle).
    return ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn"))
