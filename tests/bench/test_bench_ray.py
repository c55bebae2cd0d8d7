"""The Ray backend: the same records as the local process pool for the same seeds, resume
(also across backends, and after a kill), and a dying worker recorded as an error."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from activeintent.bench.runner import run_bench
from activeintent.bench.work import BenchConfig
from activeintent.results import read_results
from activeintent.runner import RunSpec

ray = pytest.importorskip("ray")

METHODS = ["bayes-stop", "zero-signal"]
INTENTIONS = ["stack", "color-match"]
COMPARED = ("method", "intention", "trial", "seed", "success_at", "signals_used", "answers", "final_goal")


def tiny(backend: str = "local", **changes) -> BenchConfig:
    options = BenchConfig(methods=METHODS, intentions=INTENTIONS, trials=1, seed=5, jobs=2, backend=backend,
                           run=RunSpec.from_options(budget=2, test_pool=10, llm="none", env="symbolic", video="none"))
    return options.model_copy(update=changes)


def outcomes(records: list[dict]) -> list[tuple]:
    return sorted(tuple(json.dumps(r[k], sort_keys=True) for k in COMPARED) for r in records)


def keys(path: Path) -> list[tuple]:
    return [(r["method"], r["intention"], r["trial"]) for r in read_results(path)]


@pytest.fixture(scope="module")
def local_ray():
    """A Ray of two CPUs in this process; the backend uses it and leaves it running."""
    ray.init(address="local", num_cpus=2, include_dashboard=False, object_store_memory=128 * 2**20,
             log_to_driver=False)
    try:
        yield
    finally:
        ray.shutdown()


def test_ray_gives_the_records_of_the_local_backend(tmp_path, local_ray):
    seen = []
    records = run_bench(tiny("ray"), tmp_path / "ray", on_done=lambda r, done, total: seen.append((done, total)))
    on_ray = read_results(tmp_path / "ray" / "results.jsonl")
    assert len(records) == len(on_ray) == 4 and not any(r.get("error") for r in on_ray)
    assert seen[0] == (0, 4) and seen[-1] == (4, 4) and len(seen) == 5  # progress, as on the local backend
    local = run_bench(tiny("local", jobs=1), tmp_path / "local")
    assert outcomes(on_ray) == outcomes(local)


def test_a_bench_resumes_on_the_other_backend(tmp_path, local_ray):
    out = tmp_path / "b"
    run_bench(tiny("local", methods=METHODS[1:], jobs=1), out)
    assert len(keys(out / "results.jsonl")) == 2
    records = run_bench(tiny("ray"), out)  # the backend is not a setting the resume check compares
    assert len(records) == 4
    assert sorted(keys(out / "results.jsonl")) == sorted(set(keys(out / "results.jsonl")))
    assert len(keys(out / "results.jsonl")) == 4


CRASHING_INTENTION = '''
import os

from activeintent.intentions.registry import get_intention

_stack = get_intention("stack")


class Crash(type(_stack)):
    """`stack`, except that judging a scene ends the worker process (as a native crash would)."""

    name = "crash"

    def feasible(self, scene):
        os._exit(3)
'''


def test_a_dying_ray_worker_is_recorded_and_the_bench_goes_on(tmp_path, local_ray):
    path = tmp_path / "crash.py"
    path.write_text(CRASHING_INTENTION)
    options = tiny("ray", methods=["zero-signal"], intentions=["stack"], intention_files=[f"{path}:Crash"])
    records = run_bench(options, tmp_path / "out")
    by = {r["intention"]: r for r in records}
    assert len(records) == 2
    assert "worker process died" in by[f"{path}:Crash"]["error"]
    assert not by["stack"].get("error")


# Behaves as `stack`, but judging waits until the test creates the flag file: the bench cannot
# finish before it is killed, however fast the machine (no race with the kill).
WAITING_INTENTION = '''
import time
from pathlib import Path

from activeintent.intentions.registry import get_intention

_stack = get_intention("stack")
FLAG = Path({flag!r})


class Waits(type(_stack)):
    name = "waits"

    def feasible(self, scene):
        while not FLAG.exists():
            time.sleep(0.05)
        return super().feasible(scene)
'''


@pytest.mark.slow
def test_a_killed_ray_bench_resumes_without_duplicates(tmp_path):
    flag = tmp_path / "go"
    plugin = tmp_path / "waits.py"
    plugin.write_text(WAITING_INTENTION.format(flag=str(flag)))
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "activeintent.cli", "bench", "--no-oracle", "--backend", "ray", "--jobs", "2",
           "--methods", ",".join(METHODS), "--intentions", ",".join(INTENTIONS), "--intention-file",
           f"{plugin}:Waits", "--trials", "1", "--budget", "2", "--seed", "9", "--llm", "none",
           "--env", "symbolic", "--out", str(out)]
    env = {**os.environ, "RAY_ADDRESS": ""}  # a Ray of its own, not one this machine may run
    # The four ordinary episodes come first (and fill the in-flight window); the two that wait follow.
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                            start_new_session=True)
    results = out / "results.jsonl"
    deadline = time.monotonic() + 300
    try:
        while time.monotonic() < deadline and proc.poll() is None and (
                not results.exists() or len(results.read_text().splitlines()) < 2):
            time.sleep(0.1)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    done_before = len(read_results(results))
    assert 2 <= done_before <= 4
    flag.touch()
    finished = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert finished.returncode == 0, finished.stdout[-2000:] + finished.stderr[-2000:]
    found = keys(results)
    assert len(found) == len(set(found)) == 6
    assert not any(r.get("error") for r in read_results(results))
