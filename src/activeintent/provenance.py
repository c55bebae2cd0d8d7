"""Where a result was made: package version, git commit (and whether the tree had uncommitted
changes), Python, numpy, llama.cpp and PyBullet versions, CPU model, the BLAS settings a
machine may impose, and the date. Written into every ``summary.json`` and every
results line of ``bench`` (an episode's record). ``bench-verify`` compares none of it.
"""

from __future__ import annotations

import datetime as dt
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

from activeintent.memo import memoized

# Results folders and scratch runs are written inside the checkout: they do not make it "dirty".
_NOT_CODE = (":(exclude)docs/results", ":(exclude)runs", ":(exclude,glob)experiments/*/results/**")
_BLAS_ENV = ("OPENBLAS_CORETYPE", "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def _version(dist: str) -> str | None:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


def _git(*args: str) -> str | None:
    root = Path(__file__).resolve().parents[2]
    try:
        out = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, timeout=10, check=True)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip()


@memoized(size=1, why="no arguments: the machine's CPU, constant within a process")
def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


@memoized(size=1, why="no arguments: the code a result comes from, constant within a process")
def code_version() -> dict:
    """The code a result comes from (constant within a process)."""
    commit = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--untracked-files=no", "--", ".", *_NOT_CODE) if commit else None
    return {"package": _version("activeintent"), "commit": commit,
            "dirty": None if status is None else bool(status)}


def provenance() -> dict:
    """Everything above, with the time now (UTC)."""
    return {
        **code_version(),
        "python": platform.python_version(),
        "numpy": _version("numpy"),
        "llama_cpp": _version("llama_cpp_python"),
        "pybullet": _version("pybullet"),
        "cpu": cpu_model(),
        "cores": os.cpu_count(),
        "platform": platform.platform(),
        "blas_env": {k: os.environ[k] for k in _BLAS_ENV if k in os.environ},
        "date": dt.datetime.now(dt.UTC).isoformat(timespec="seconds"),
    }
