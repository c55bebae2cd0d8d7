"""Session set-up shared by every test: import paths, plugins, and a private cache folder."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

# tests import helpers.py (and the suite_rules plugin) as plain modules
sys.path.insert(0, str(Path(__file__).parent))

# suite_rules: per-test timeouts, and CI failing on missing core dependencies.
# pytester: tests of those rules run small pytest sessions of their own.
pytest_plugins = ["pytester", "suite_rules"]

# The code keeps its caches under the home folder (~/.cache/activeintent: the hypothesis space,
# model responses, the assembled GGUF, the light Panda model) or under ACTIVEINTENT_CACHE.
# A run points all of them at a fresh temporary home, so it neither reads stale results from the
# user's caches nor writes into them. This happens in pytest_configure rather than in a fixture
# because collection already imports the code (and could read a cache).
# The language's hypothesis spaces are the exception: content-addressed (the hash of their
# sources is in the file name), minutes to build, so kept in the checkout's .pytest_cache and
# shared by the run's workers (one builds, the others wait for it and read it).
_CACHE_VARIABLES = ("HOME", "XDG_CACHE_HOME", "ACTIVEINTENT_CACHE", "ACTIVEINTENT_SPACE_CACHE")
_saved_environment: dict[str, str | None] = {}
_temporary_root: list[Path] = []


def pytest_configure(config: pytest.Config) -> None:
    root = Path(tempfile.mkdtemp(prefix="activeintent-tests-"))
    home = root / "home"
    values = {
        "HOME": home,
        "XDG_CACHE_HOME": home / ".cache",
        "ACTIVEINTENT_CACHE": home / ".cache" / "activeintent",
        "ACTIVEINTENT_SPACE_CACHE": Path(config.rootpath) / ".pytest_cache" / "activeintent-spaces",
    }
    values["ACTIVEINTENT_CACHE"].mkdir(parents=True)
    try:
        values["ACTIVEINTENT_SPACE_CACHE"].mkdir(parents=True, exist_ok=True)
    except OSError:  # a checkout this user may not write to: the run's own home then
        values["ACTIVEINTENT_SPACE_CACHE"] = values["ACTIVEINTENT_CACHE"]
    for name, value in values.items():
        _saved_environment[name] = os.environ.get(name)
        os.environ[name] = str(value)
    _temporary_root.append(root)


def pytest_sessionstart(session: pytest.Session) -> None:
    """In CI, before the workers start: the default language's two starting spaces (length and
    fitted prior), built side by side, so that no test waits minutes for one."""
    if not os.environ.get("CI") or hasattr(session.config, "workerinput"):
        return
    code = ("import sys; from activeintent.learners.lang.hypotheses import lang_space; "
            "from activeintent.learners.lang.learner import KEEP; lang_space(0, KEEP, sys.argv[1])")
    builds = [subprocess.Popen([sys.executable, "-c", code, prior]) for prior in ("length", "fitted")]
    for build in builds:
        build.wait()


def pytest_unconfigure(config: pytest.Config) -> None:
    for name, value in _saved_environment.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value
    _saved_environment.clear()
    while _temporary_root:
        shutil.rmtree(_temporary_root.pop(), ignore_errors=True)


@pytest.fixture(scope="session")
def run_home() -> Path:
    """The temporary home folder of this run (its .cache holds every cache the code writes)."""
    return Path(os.environ["HOME"])
