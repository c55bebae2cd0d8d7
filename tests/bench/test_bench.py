"""The benchmark: tiny runs complete under the protocol, report intervals and baselines,
resume after a kill, refuse mixed settings, reproduce, and take plug-in signals."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from activeintent.bench.report import wilson, write_report
from activeintent.bench.runner import run_bench
from activeintent.bench.work import BenchConfig
from activeintent.protocol import FORMAT_VERSION, trial_seeds
from activeintent.results import read_results
from activeintent.runner import RunSpec

ROOT = Path(__file__).resolve().parents[2]
METHODS = ["bayes-stop", "zero-signal"]
INTENTIONS = ["stack", "color-match"]
PROTOCOL = ("env", "budget", "new_scene", "test_scenes", "test_pool")  # and the whole spec: config.spec


def tiny(jobs: int = 1, **run) -> BenchConfig:
    return BenchConfig(methods=METHODS, intentions=INTENTIONS, trials=1, seed=5, jobs=jobs,
                        run=RunSpec.from_options(budget=2, llm="none", env="symbolic", video="none", **run))


def test_wilson_interval_matches_known_values():
    lo, hi = wilson(3, 5)
    assert round(lo, 3) == 0.231 and round(hi, 3) == 0.882
    assert wilson(0, 5)[0] == 0.0 and wilson(5, 5)[1] == 1.0


CELL = re.compile(r"([0-9.]+) \[([0-9.]+), ([0-9.]+)\] \(n=(\d+)\)")


def test_report_intervals_are_wilson_intervals_of_the_episodes(tmp_path):
    """Every printed cell is mean [Wilson interval of Σ success over n] (n=n), n = the scored
    episodes of that cell (errors and unscored episodes left out), for each intention and 'all'."""
    successes = {("bayes-stop", "stack"): [1.0, 0.5, 0.8, 0.9, 0.7, 1.0],
                 ("bayes-stop", "color-match"): [0.2, 0.0, 0.4],
                 ("zero-signal", "stack"): [0.1, 0.3, 0.0, 0.0],
                 ("zero-signal", "color-match"): [0.6, 0.9, 0.75, 0.3, 0.5]}
    records = []
    for (method, intention), values in successes.items():
        for trial, v in enumerate(values):
            records.append({"method": method, "intention": intention, "trial": trial, "success": v,
                            "success_at": [0.0, v], "signals_used": 1, "answers": {"stop": 1}})
        records.append({"method": method, "intention": intention, "trial": 99, "error": "boom", "success": None})
        records.append({"method": method, "intention": intention, "trial": 98, "success": None})
    text = write_report(records, METHODS, INTENTIONS, tmp_path, {"env": "symbolic", "budget": 1}).read_text()
    checked = 0
    for method in METHODS:
        row = next(line for line in text.splitlines() if line.startswith(f"| {method} |")
                   or line.startswith(f"| *{method}* (baseline) |"))
        cells = CELL.findall(row)
        assert len(cells) == len(INTENTIONS) + 1, row
        columns = [successes[(method, i)] for i in INTENTIONS]
        columns.append([v for values in columns for v in values])  # the **all** column
        for (mean, lo, hi, n), values in zip(cells, columns, strict=True):
            want_lo, want_hi = wilson(sum(values), len(values))
            assert int(n) == len(values)
            assert float(mean) == pytest.approx(round(sum(values) / len(values), 2), abs=1e-9)
            assert (float(lo), float(hi)) == pytest.approx((round(want_lo, 2), round(want_hi, 2)), abs=1e-9), row
            checked += 1
    assert checked == 6


def test_the_report_prints_what_the_answers_told_the_learner(tmp_path):
    def rows(*kinds_bits):
        return {"answers": [{"answer": k, "kl_bits": b, "gain_bits": 1.0, "shown_mass": 0.5, "top": []}
                            for k, b in kinds_bits]}

    records = [{"method": "bayes-stop", "intention": "stack", "trial": t, "success": 0.5, "success_at": [0.0, 0.5],
                "signals_used": 2, "answers": {}, "diagnostics": d}
               for t, d in enumerate([rows(("stop", 1.5), ("new_scene", 0.3)), rows(("stop", 0.9), ("no_stop", 0.5))])]
    text = write_report(records, ["bayes-stop"], ["stack"], tmp_path, {"env": "symbolic", "budget": 2}).read_text()
    (row,) = [line for line in text.splitlines() if line.startswith("| paper | bayes-stop |")]
    assert "| 4 (2) |" in row and "new_scene 25%, no_stop 25%, stop 50%" in row
    assert "| 0.80 |" in row and "stop 1.20" in row and "new_scene 0.30" in row and "| 0.50 |" in row


def test_trial_seeds():
    assert trial_seeds(5, "stack", 0)[1] == trial_seeds(5, "color-match", 0)[1]  # test scenes: per trial only
    assert trial_seeds(5, "stack", 0)[0] != trial_seeds(5, "color-match", 0)[0]
    assert trial_seeds(5, "stack", 0) != trial_seeds(5, "stack", 1)


def test_tiny_bench_records_the_protocol_and_reports_intervals_and_baselines(tmp_path):
    records = run_bench(tiny(), tmp_path / "one")
    assert len(records) == 4 and not any(r.get("error") for r in records)
    for r in records:
        assert r["format"] == FORMAT_VERSION and all(k in r for k in PROTOCOL)
        assert len(r["success_at"]) == 3 and r["test_scenes"] >= 10
        assert r["signals_used"] == (2 if r["method"] == "bayes-stop" else 0)
        spec = r["config"]["spec"]
        assert spec["user"]["preset"] == "human" and r["new_scene"] == "counted" == spec["protocol"]["new_scene"]
        assert spec["learner"] == {"method": r["method"], "settings": {"prior": "length", "scenes": "sampled"}}
    report = write_report(records, METHODS, INTENTIONS, tmp_path / "one",
                          {"env": "symbolic", "budget": 2, "trials": 1}).read_text()
    assert "*zero-signal* (baseline)" in report and "(n=1)" in report and "Wilson" in report
    assert "**Env: symbolic**" in report
    again = run_bench(tiny(), tmp_path / "two")
    keep = ("method", "intention", "trial", "seed", "success_at", "signals_used", "answers", "final_goal")
    assert [{k: r[k] for k in keep} for r in records] == [{k: r[k] for k in keep} for r in again]


def test_resume_skips_finished_and_drops_a_torn_line(tmp_path):
    out = tmp_path / "b"
    first = run_bench(BenchConfig(**{**tiny().model_dump(), "methods": METHODS[1:]}), out)
    assert len(first) == 2
    with (out / "results.jsonl").open("a") as f:
        f.write('{"method": "bayes-stop", "intent')  # a write cut off by a kill
    records = run_bench(tiny(), out)
    lines = (out / "results.jsonl").read_text().splitlines()
    keys = [(json.loads(x)["method"], json.loads(x)["intention"], json.loads(x)["trial"]) for x in lines]
    assert len(keys) == len(set(keys)) == 4 == len(records)


def test_resume_refuses_other_settings(tmp_path):
    run_bench(BenchConfig(**{**tiny().model_dump(), "trials": 1, "methods": ["zero-signal"]}), tmp_path)
    with pytest.raises(ValueError, match="other settings"):
        run_bench(tiny(user="exact"), tmp_path)


def test_a_plugin_signal_runs_in_bench_without_package_changes(tmp_path):
    plugin = str(ROOT / "examples" / "my_signal.py")
    options = BenchConfig(methods=["bayes-rating"], intentions=["stack"], trials=1, seed=1,
                           run=RunSpec.from_options(budget=3, llm="none", env="symbolic", video="none", plugin=[plugin]))
    (r,) = run_bench(options, tmp_path)
    assert r.get("error") is None and r["method"] == "bayes-rating"
    assert r["signals_used"] == 3 and set(r["answers"]) <= {"rating", "new_scene"}


def test_bench_refuses_setups_that_cannot_run(tmp_path):
    def bench(*args):
        return subprocess.run([sys.executable, "-m", "activeintent.cli", "bench", *args, "--out", str(tmp_path)],
                              capture_output=True, text=True, timeout=120)

    no_model = bench("--methods", "preference", "--llm", "none")
    assert no_model.returncode == 2 and "needs a language model" in no_model.stdout
    nothing = bench("--intentions", "", "--suite", "")
    assert nothing.returncode == 2 and "no intentions" in nothing.stdout
    unknown = bench("--methods", "bayes-nope")
    assert unknown.returncode == 2 and "valid methods" in unknown.stdout


@pytest.mark.slow
def test_killed_bench_resumes_without_duplicates(tmp_path):
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "activeintent.cli", "bench", "--no-oracle", "--methods", ",".join(METHODS), "--intentions",
           "stack,color-match,align", "--trials", "2", "--budget", "2", "--seed", "9", "--llm", "none",
           "--env", "symbolic", "--out", str(out)]
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
    assert (out / "report.md").exists() and (out / "success_vs_signals.png").stat().st_size > 0


@pytest.mark.slow
def test_parallel_jobs_give_the_same_results(tmp_path):
    serial = run_bench(tiny(), tmp_path / "serial")
    parallel = run_bench(tiny(jobs=2), tmp_path / "parallel")
    key = lambda r: (r["method"], r["intention"], r["trial"])  # noqa: E731
    pick = lambda r: (key(r), r["success_at"], r["final_goal"], r["signals_used"])  # noqa: E731
    assert sorted(map(pick, serial)) == sorted(map(pick, parallel))


CRASHING_INTENTION = '''
import os

from activeintent.intentions.registry import get_intention

_stack = get_intention("stack")


class Crash(type(_stack)):
    """Behaves as `stack`, but its worker process dies (as on a native crash) when judged."""

    name = "crash"

    def feasible(self, scene):
        os._exit(3)
'''


@pytest.mark.slow
def test_a_dying_worker_is_recorded_and_the_bench_goes_on(tmp_path):
    path = tmp_path / "crash.py"
    path.write_text(CRASHING_INTENTION)
    options = BenchConfig(methods=["zero-signal"], intentions=["stack"], intention_files=[f"{path}:Crash"],
                           trials=1, seed=5, jobs=2, run=RunSpec.from_options(budget=1, llm="none", env="symbolic", video="none"))
    records = run_bench(options, tmp_path / "out")
    by = {r["intention"]: r for r in records}
    assert len(records) == 2
    assert "worker process died" in by[f"{path}:Crash"]["error"]
    assert not by["stack"].get("error")
