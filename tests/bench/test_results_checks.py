"""A results folder trusts only what its own plan could have made (issue 58, B1 and B2): records
checked against the folder's bench.json and against themselves on resume, in the report and in
bench-verify; an episode recorded twice settled by running it again; the writer's lock held on
the folder itself, so removing its note file cannot let a second bench in. Against real bench
runs and files."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from typer.testing import CliRunner

from activeintent.cli import app
from activeintent.protocol import trial_seeds
from activeintent.results import hold_results_folder, load_results, read_results
from activeintent.spec import EpisodeSeeds, RunSpec

TINY = ["--no-oracle", "--methods", "zero-signal", "--intentions", "color-match", "--budget", "2", "--test-scenes", "2",
        "--test-pool", "0", "--env", "symbolic", "--llm", "none", "--seed", "3"]
cli = CliRunner()


def bench(out: Path, trials: int):
    res = cli.invoke(app, ["bench", *TINY, "--trials", str(trials), "--out", str(out)])
    assert res.exit_code == 0, res.output
    return res


def lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def test_records_that_do_not_belong_to_the_folder_are_set_aside_and_reported(tmp_path):
    """B1: before, every one of these was kept and counted (a `--trials 2` folder reported n = 3
    with a copied trial 7)."""
    bench(tmp_path, 2)
    results = tmp_path / "results.jsonl"
    real = lines(results)[1]  # trial 1
    seed, test_seed = trial_seeds(3, "color-match", 2)
    trial2 = {**real, "trial": 2, "seed": seed, "test_seed": EpisodeSeeds.from_seed(seed, test_seed).test}
    fake_commit = "0123456789" * 4

    def spec_with(section: str, field: str, value) -> dict:
        spec = {**trial2["config"]["spec"], section: {**trial2["config"]["spec"][section], field: value}}
        return {**trial2, "config": {**trial2["config"], "spec": spec}}

    forged = {  # each wrong in one way only
        "trial 7 of a --trials 3 folder": {**real, "trial": 7},
        "another env": spec_with("env", "name", "pybullet"),
        "an env its own spec contradicts": {**trial2, "env": "pybullet"},
        "another budget": {**trial2, "budget": 9},
        "another user preset": spec_with("user", "preset", "exact"),
        "another model": spec_with("models", "llm", "openai:qwen"),
        "another executor": spec_with("act", "executor", "cap"),
        "another prior": spec_with("learner", "settings", {"prior": "uniform", "scenes": "sampled"}),
        "another method": {**trial2, "method": "bayes-stop"},
        "another trial's seeds": {**real, "trial": 2},
        "a false provenance": {**trial2, "provenance": {**real["provenance"], "commit": fake_commit}},
        "format 99": {**trial2, "format": 99},
        "a success its own curve contradicts": {**trial2, "success": 1.0},
    }
    with results.open("a") as f:
        f.write("".join(json.dumps(r) + "\n" for r in forged.values()))
    res = bench(tmp_path, 3)
    text = " ".join(res.output.split())
    assert f"{len(forged)} line(s) of results.jsonl not trusted" in text
    kept = lines(results)
    assert sorted(r["trial"] for r in kept) == [0, 1, 2]  # trial 2 really run, n = 3
    assert all(r["env"] == "symbolic" and r["config"]["spec"]["models"]["llm"] == "none" and r["format"] == 3
               for r in kept)
    aside = lines(tmp_path / "rejected.jsonl")
    assert len(aside) == len(forged)
    reasons = [r["reason"] for r in aside]
    for why, expect in zip(reasons, ["trial 7 is past", "env.name 'pybullet'", "env 'pybullet' (its spec's 'symbolic')",
                                     "budget 9", "user.preset 'exact'", "models.llm 'openai:qwen'",
                                     "act.executor 'cap'", "learner.settings.prior 'uniform'",
                                     "method 'bayes-stop'", "seed ",
                                     "not in this checkout's history", "format 99", "curve's last value"], strict=True):
        assert expect in why, (expect, why)
    report = " ".join((tmp_path / "report.md").read_text().split())
    assert f"**Set aside:** {len(forged)} line(s)" in report and "not of this folder's plan" in report


def test_a_forged_duplicate_before_the_real_record_loses_to_a_rerun(tmp_path):
    """B1: before, the first valid record of an episode won, so a forged one placed before the
    real one replaced it. Now a reader sets both aside, bench-verify fails the folder, and a
    resume runs the episode once more and keeps the record equal to that run."""
    bench(tmp_path, 1)
    results = tmp_path / "results.jsonl"
    real_bytes = results.read_bytes()
    real = json.loads(real_bytes)
    forged = {**real, "success": 1.0, "success_at": [1.0, 1.0, 1.0], "final_z": "all blocks go left"}
    results.write_bytes(json.dumps(forged).encode() + b"\n" + real_bytes)

    assert read_results(results) == []  # a reader cannot tell which is real: neither counts
    verified = cli.invoke(app, ["bench-verify", str(tmp_path), "--sample", "1"])
    assert verified.exit_code == 1, verified.output
    assert "line 1 not trusted (duplicate)" in verified.output and "line 2 not trusted (duplicate)" in verified.output

    res = bench(tmp_path, 1)
    assert "another one equals the episode run again" in " ".join(res.output.split())
    assert results.read_bytes() == real_bytes  # the real record, byte for byte
    (aside,) = lines(tmp_path / "rejected.jsonl")
    assert aside["kind"] == "duplicate" and aside["line"] == 1 and json.loads(aside["text"]) == forged
    assert cli.invoke(app, ["bench-verify", str(tmp_path), "--sample", "1"]).exit_code == 0


def test_bench_verify_checks_every_record_not_only_its_sample(tmp_path):
    bench(tmp_path, 2)
    results = tmp_path / "results.jsonl"
    real = lines(results)[0]
    with results.open("a") as f:  # a record of trial 5 of a 2-trial folder, past any sample
        f.write(json.dumps({**real, "trial": 5}) + "\n")
    res = cli.invoke(app, ["bench-verify", str(tmp_path), "--sample", "1"])
    assert res.exit_code == 1, res.output
    assert "line 3 not trusted (plan): trial 5 is past" in " ".join(res.output.split())
    assert len(load_results(results).records) == 3  # bench-verify reads only


def test_removing_the_lock_file_does_not_let_a_second_bench_in(tmp_path):
    """B2: before, the lock was the file OUT/.lock: `rm OUT/.lock` during a run let a second bench
    write beside the first."""
    cmd = [sys.executable, "-m", "activeintent.cli", "bench", *TINY, "--trials", "100", "--out", str(tmp_path)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        results = tmp_path / "results.jsonl"
        while time.monotonic() < deadline and not (results.exists() and results.read_bytes().count(b"\n") >= 1):
            assert proc.poll() is None, "the first bench ended early"
            time.sleep(0.1)
        for name in os.listdir(tmp_path):
            if name.startswith(".lock"):
                os.remove(tmp_path / name)
        second = cli.invoke(app, ["bench", *TINY, "--trials", "100", "--out", str(tmp_path)])
        assert second.exit_code == 2, second.output[-2000:]
        assert "being written by another process" in " ".join(second.output.split())
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    keys = [(r["method"], r["intention"], r["trial"]) for r in lines(tmp_path / "results.jsonl")]
    assert len(keys) == len(set(keys))
    with hold_results_folder(tmp_path):  # released with the killed holder
        pass


def test_a_record_of_the_older_shape_equal_to_the_rerun_is_the_one_kept(tmp_path):
    """Duplicates are settled as bench-verify compares: a record written before the spec was kept
    whole (flat options, settings repeated at its top) is read in today's shape first."""
    bench(tmp_path, 1)
    results = tmp_path / "results.jsonl"
    real = json.loads(results.read_bytes())
    options = {k: v for k, v in RunSpec.model_validate(real["config"]["spec"]).options().items() if k != "plugin"}
    old = {**{k: v for k, v in real.items() if k != "config"}, "user_preset": "human", "prior": "length",
           "llm": "none", "vlm": None, "executor": "plan", "retriever": "symbolic", "variant": "faithful",
           "config": {"episode": real["config"]["episode"], "options": {**options, "plugins": []}}}
    old_bytes = json.dumps(old).encode() + b"\n"
    forged = {**old, "success": 1.0, "success_at": [1.0, 1.0, 1.0]}
    results.write_bytes(json.dumps(forged).encode() + b"\n" + old_bytes)
    res = bench(tmp_path, 1)
    assert "another one equals the episode run again" in " ".join(res.output.split())
    assert results.read_bytes() == old_bytes
