"""The benchmark: tiny runs complete, report the right rows, resume after a kill, reproduce."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from activeintent.bench.report import wilson, write_report
from activeintent.bench.runner import BenchOptions, WorkItem, episode_seed, read_results, run_bench
from activeintent.runner import RunOptions

METHODS = ["bayes-preference", "bayes-stop"]
INTENTIONS = ["stack", "color-match"]


def tiny(jobs: int = 1) -> BenchOptions:
    return BenchOptions(methods=METHODS, intentions=INTENTIONS, trials=1, seed=5, jobs=jobs,
                        run=RunOptions(rounds=2, save_videos=False, llm="none"))


def test_wilson_interval_matches_known_values():
    lo, hi = wilson(3, 5)
    assert round(lo, 3) == 0.231 and round(hi, 3) == 0.882
    assert wilson(0, 5)[0] == 0.0 and wilson(5, 5)[1] == 1.0


def test_trial_seeds_are_shared_by_methods_and_differ_by_trial():
    a = WorkItem(method="bayes-stop", intention="stack", trial=0)
    b = WorkItem(method="preference", intention="stack", trial=0)
    assert episode_seed(5, a.intention, a.trial) == episode_seed(5, b.intention, b.trial)
    assert episode_seed(5, "stack", 0) != episode_seed(5, "stack", 1)


def test_tiny_bench_completes_with_report_and_reproduces(tmp_path):
    records = run_bench(tiny(), tmp_path / "one")
    assert len(records) == 4 and not any(r.get("error") for r in records)
    assert {(r["method"], r["intention"]) for r in records} == {(m, i) for m in METHODS for i in INTENTIONS}
    for r in records:
        assert r["signals_used"] <= 2 and len(r["per_round_success"]) == r["rounds_used"]
        assert set(r["time_split"]) == {"sim_s", "render_s", "model_s"}
    report = write_report(records, METHODS, INTENTIONS, tmp_path / "one", {"trials": 1}).read_text()
    rows = [line for line in report.splitlines() if line.startswith("| bayes-")]
    assert [r.split(" | ")[0] for r in rows] == ["| bayes-preference", "| bayes-stop"]
    assert "(paper)" in report and "| mllm-llm (paper) | 0.4 | 0.8 | 0.60 |" in report  # columns that were run
    again = run_bench(tiny(), tmp_path / "two")
    keep = ("method", "intention", "trial", "seed", "success", "signals_used", "final_preference", "final_goal",
            "per_round_success")
    assert [{k: r[k] for k in keep} for r in records] == [{k: r[k] for k in keep} for r in again]


def test_resume_skips_finished_and_drops_a_torn_line(tmp_path):
    out = tmp_path / "b"
    first = run_bench(BenchOptions(**{**tiny().model_dump(), "methods": METHODS[:1]}), out)
    assert len(first) == 2
    with (out / "results.jsonl").open("a") as f:
        f.write('{"method": "bayes-stop", "intent')  # a write cut off by a kill
    records = run_bench(tiny(), out)
    lines = (out / "results.jsonl").read_text().splitlines()
    keys = [(json.loads(x)["method"], json.loads(x)["intention"], json.loads(x)["trial"]) for x in lines]
    assert len(keys) == len(set(keys)) == 4 == len(records)


@pytest.mark.slow
def test_killed_bench_resumes_without_duplicates(tmp_path):
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "activeintent.cli", "bench", "--methods", ",".join(METHODS), "--intentions",
           "stack,color-match,align", "--trials", "2", "--rounds", "2", "--seed", "9", "--llm", "none", "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    results = out / "results.jsonl"
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline and (not results.exists() or len(results.read_text().splitlines()) < 2):
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    done_before = len(read_results(results))
    assert 2 <= done_before < 12
    finished = subprocess.run(cmd, capture_output=True, text=True, timeout=1200)
    assert finished.returncode == 0, finished.stdout[-2000:] + finished.stderr[-2000:]
    records = read_results(results)
    keys = [(r["method"], r["intention"], r["trial"]) for r in records]
    assert len(keys) == len(set(keys)) == 12
    assert (out / "report.md").exists() and (out / "success_vs_rounds.png").stat().st_size > 0


@pytest.mark.slow
def test_parallel_jobs_give_the_same_results(tmp_path):
    serial = run_bench(tiny(), tmp_path / "serial")
    parallel = run_bench(tiny(jobs=2), tmp_path / "parallel")
    key = lambda r: (r["method"], r["intention"], r["trial"])  # noqa: E731
    pick = lambda r: (key(r), r["success"], r["final_goal"], r["signals_used"])  # noqa: E731
    assert sorted(map(pick, serial)) == sorted(map(pick, parallel))
    assert Path(tmp_path / "parallel" / "episodes").is_dir()


CRASHING_INTENTION = '''
import os

from activeintent.intentions.registry import get_intention

_stack = get_intention("stack")


class Crash(type(_stack)):
    """Behaves as `stack`, but its worker process dies (as on a native crash) when sampling."""

    name = "crash"

    def sample_scene(self, rng):
        os._exit(3)
'''


@pytest.mark.slow
def test_a_dying_worker_is_recorded_and_the_bench_goes_on(tmp_path):
    path = tmp_path / "crash.py"
    path.write_text(CRASHING_INTENTION)
    options = BenchOptions(methods=["bayes-stop"], intentions=["stack"], intention_files=[f"{path}:Crash"],
                           trials=1, seed=5, jobs=2, run=RunOptions(rounds=1, save_videos=False, llm="none"))
    records = run_bench(options, tmp_path / "out")
    by = {r["intention"]: r for r in records}
    assert len(records) == 2
    assert "worker process died" in by[f"{path}:Crash"]["error"]
    assert not by["stack"].get("error")


def test_resume_refuses_other_settings(tmp_path):
    run_bench(BenchOptions(**{**tiny().model_dump(), "trials": 0}), tmp_path)  # writes bench.json only
    other = tiny()
    other.run.rounds = 3
    with pytest.raises(ValueError, match="other settings"):
        run_bench(other, tmp_path)
