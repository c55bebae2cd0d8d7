"""Bit-for-bit episodes on every machine: the same bench folder re-run in fresh processes under
other BLAS kernels and thread counts, other string-hash seeds (a set iterated in a planner once
made episodes follow PYTHONHASHSEED) and with an empty cache directory, gives identical records
(everything but wall time, its split and provenance)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from activeintent import ranking

ROOT = Path(__file__).resolve().parents[2]

# bayes-stop: EIG + final expected success (the near-ties that used to follow the BLAS kernel);
# lang-preference: the goal-language space built from an empty cache, two-outcome queries.
BENCH = ["bench", "--no-oracle", "--methods", "bayes-stop,lang-preference,zero-signal", "--intentions", "align,dev-warm-on-cool",
         "--trials", "1", "--budget", "3", "--test-pool", "10", "--env", "symbolic", "--llm", "none"]


def _cli(args: list[str], cache: Path, **env: str) -> subprocess.CompletedProcess:
    full = {**os.environ, "ACTIVEINTENT_CACHE": str(cache), **env}
    for key in ("OPENBLAS_CORETYPE", "OPENBLAS_NUM_THREADS", "PYTHONHASHSEED"):
        if key not in env:
            full.pop(key, None)
    return subprocess.run([sys.executable, "-m", "activeintent.cli", *args], capture_output=True, text=True,
                          env=full, cwd=ROOT, timeout=800)


@pytest.mark.slow
def test_episodes_are_identical_under_other_blas_kernels_threads_and_an_empty_cache(tmp_path):
    folder = tmp_path / "bench"
    made = _cli([*BENCH, "--out", str(folder)], tmp_path / "cache-a", PYTHONHASHSEED="0")
    assert made.returncode == 0, made.stderr[-2000:]
    lines = [json.loads(x) for x in (folder / "results.jsonl").read_text().splitlines()]
    assert len(lines) == 6 and not any(r.get("error") for r in lines)
    for kernel, threads, hashing in [("Haswell", "1", "1"), ("Prescott", "2", "2")]:
        again = _cli(["bench-verify", str(folder), "--sample", "6"], tmp_path / f"cache-{kernel}",
                     OPENBLAS_CORETYPE=kernel, OPENBLAS_NUM_THREADS=threads, PYTHONHASHSEED=hashing)
        assert again.returncode == 0, f"{kernel}, {threads} thread(s):\n{again.stdout[-4000:]}{again.stderr[-2000:]}"
        assert "6 re-run episodes agree" in again.stdout
        assert any((tmp_path / f"cache-{kernel}").iterdir()), "the empty cache directory was not used"


def test_choices_among_near_ties_ignore_float_noise():
    """Two values equal but for the last bits (e.g. two BLAS summation orders) tie, and the tie
    goes to the first index, whichever of them the noise made larger."""
    a = np.array([0.1, 0.2, 0.3]).sum()  # 0.6000000000000001
    b = 0.6
    assert a != b
    assert ranking.argmax([b, a]) == 0 and ranking.argmax([a, b]) == 0
    assert list(ranking.order([0.1, a, b])) == [1, 2, 0]
    assert not ranking.greater(a, b) and not ranking.greater(b, a)
    assert ranking.argmax([0.5, 0.5 + 1e-6]) == 1  # a real difference still counts


def test_a_final_answer_runs_the_shorter_of_two_equally_good_plans():
    """ranking.best_plan, the tie-break of every learner's final answer: equal values (even
    equal only up to float noise) go to the shorter plan; a real difference in value beats
    any difference in length of a few steps."""
    a = np.array([0.1, 0.2, 0.3]).sum()  # 0.6000000000000001
    assert ranking.best_plan([a, 0.6], [4, 2]) == 1 and ranking.best_plan([0.6, a], [2, 4]) == 0
    assert ranking.best_plan([0.6, 0.6], [3, 3]) == 0  # then the first
    assert ranking.best_plan([0.6, 0.61], [1, 6]) == 1
