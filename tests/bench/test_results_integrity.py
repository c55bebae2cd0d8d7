"""Nothing lost, nothing hung: the results folder of a bench under kills, corrupt or forged
lines, a missing final newline and a second bench on the same folder."""

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
from activeintent.results import hold_results_folder, load_results

ROOT = Path(__file__).resolve().parents[2]
TINY = ["--no-oracle", "--methods", "zero-signal", "--intentions", "color-match", "--budget", "2", "--test-scenes", "2",
        "--test-pool", "0", "--env", "symbolic", "--llm", "none", "--seed", "3"]
cli = CliRunner()


def bench(out: Path, trials: int, *extra: str):
    res = cli.invoke(app, ["bench", *TINY, "--trials", str(trials), *extra, "--out", str(out)])
    assert res.exit_code == 0, res.output
    return res


def keys(path: Path) -> list[tuple]:
    return [(r["method"], r["intention"], r["trial"]) for r in load_results(path).records]


def rejected(out: Path) -> list[dict]:
    path = out / "rejected.jsonl"
    return [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []


def test_a_non_utf8_line_is_set_aside_and_the_bench_resumes(tmp_path):
    bench(tmp_path, 1)
    results = tmp_path / "results.jsonl"
    good = results.read_bytes()
    results.write_bytes(b'{"method": "zero-signal", "trial": \xff\xfe}\n' + good)
    res = bench(tmp_path, 2)
    assert "not trusted" in res.output and "not UTF-8" in res.output
    assert sorted(keys(results)) == [("zero-signal", "color-match", 0), ("zero-signal", "color-match", 1)]
    assert results.read_bytes().startswith(good)  # the good line kept byte for byte
    (bad,) = rejected(tmp_path)
    assert bad["line"] == 1 and "not UTF-8" in bad["reason"] and "\\xff" in bad["text"]
    assert b"\xff" not in results.read_bytes()


def test_forged_invalid_and_duplicate_records_are_never_trusted(tmp_path):
    bench(tmp_path, 1)
    results = tmp_path / "results.jsonl"
    (line,) = results.read_text().splitlines()
    real = json.loads(line)
    forged = {"method": "zero-signal", "intention": "color-match", "trial": 1, "success": 1.0}  # the three keys only
    duplicate = {**real, "success": 1.0 - (real["success"] or 0)}  # trial 0 is already there; contradicts its curve
    wrong_type = {**real, "trial": 2, "wall_s": "slow"}  # crashed the report before
    with results.open("a") as f:
        f.write("".join(json.dumps(r) + "\n" for r in (forged, duplicate, wrong_type)))
    res = bench(tmp_path, 3)
    text = " ".join(res.output.split())
    assert "3 line(s) of results.jsonl not trusted" in text and "not its own curve's last value" in text
    records = {r["trial"]: r for r in load_results(results).records}
    assert sorted(records) == [0, 1, 2] and len(keys(results)) == 3
    assert records[0] == real  # the first valid record is kept, the forged duplicate is not
    assert records[1].get("seed") is not None and records[2]["wall_s"] != "slow"  # really run
    reasons = [r["reason"] for r in rejected(tmp_path)]
    assert len(reasons) == 3
    assert "not a valid record" in reasons[0] and "seed" in reasons[0]
    assert "curve" in reasons[1]
    assert "wall_s" in reasons[2]
    assert "| zero-signal" in (tmp_path / "report.md").read_text()


def test_an_append_to_a_file_without_final_newline_starts_a_new_line(tmp_path):
    bench(tmp_path, 1)
    results = tmp_path / "results.jsonl"
    results.write_bytes(results.read_bytes().rstrip(b"\n"))
    bench(tmp_path, 3)
    assert b"}{" not in results.read_bytes()
    assert sorted(k[2] for k in keys(results)) == [0, 1, 2]
    assert not rejected(tmp_path)


def test_a_second_bench_on_a_held_folder_refuses_naming_the_holder(tmp_path):
    with hold_results_folder(tmp_path):
        res = subprocess.run([sys.executable, "-m", "activeintent.cli", "bench", *TINY, "--trials", "1",
                              "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    text = " ".join(res.stdout.split())
    assert res.returncode == 2, res.stdout + res.stderr
    assert "being written by another process" in text and f"pid {os.getpid()}" in text
    assert not (tmp_path / "results.jsonl").exists()
    bench(tmp_path, 1)  # released: the folder is usable again
    assert len(keys(tmp_path / "results.jsonl")) == 1


def _children(pid: int) -> set[int]:
    out = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out.add(int(entry.name))
    return out


def _alive(pid: int) -> bool:
    """Running (a zombie waiting for a reaper is dead: it holds no memory and does nothing)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_pool_workers_and_resource_tracker_die_with_a_killed_bench(tmp_path):
    cmd = [sys.executable, "-m", "activeintent.cli", "bench", *TINY, "--trials", "200", "--jobs", "2",
           "--out", str(tmp_path)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    children: set[int] = set()
    try:
        deadline = time.monotonic() + 240
        results = tmp_path / "results.jsonl"
        # Wait until both workers have answered (so their initializer ran) and the tracker is up.
        while time.monotonic() < deadline and (len(children) < 3 or len(keys(results)) < 2):
            assert proc.poll() is None, "the bench ended early"
            children |= _children(proc.pid)
            time.sleep(0.2)
        assert len(children) >= 3, children  # two workers and the resource tracker
        os.kill(proc.pid, signal.SIGKILL)  # the parent alone, as `kill -9 <pid>` does
        proc.wait()
        deadline = time.monotonic() + 30  # a bound, not a timing assertion
        while time.monotonic() < deadline and any(_alive(p) for p in children):
            time.sleep(0.2)
        assert not [p for p in children if _alive(p)], "orphans outlived the bench"
        with hold_results_folder(tmp_path):  # the kill left no stale lock
            pass
    finally:
        for p in children:
            if _alive(p):
                os.kill(p, signal.SIGKILL)
        if proc.poll() is None:
            proc.kill()
