"""The test suite's own rules: CI fails on missing core dependencies, timeouts, a private cache
folder, and no fake secret left in the environment.

The CI rules are checked on small pytest sessions (pytester) that load ``suite_rules``.
"""

from __future__ import annotations

import importlib.util
import os
import pwd
import tempfile
from pathlib import Path

import pytest

import suite_rules
from activeintent.learners.bayes import hypotheses as hyp
from activeintent.llm.cache import default_cache_path
from activeintent.llm.embedded import default_model_dir

SKIPPING = '''
import pytest

def test_dependency_missing_in_a_fixture():
    pytest.skip("/nowhere/chromium is missing: apt-get install chromium")

def test_module_missing():
    pytest.importorskip("pybullet_not_installed_here")

def test_not_about_a_dependency():
    pytest.skip("only meaningful when running as root")

def test_passes():
    pass
'''

SKIPPED_AT_IMPORT = '''
import pytest

pytest.importorskip("llama_cpp_not_installed_here")

def test_never_collected():
    pass
'''


@pytest.fixture
def all_present(monkeypatch):
    """Every probe reports its dependency usable, whatever this machine has."""
    for name, dep in list(suite_rules.CORE_DEPENDENCIES.items()):
        monkeypatch.setitem(suite_rules.CORE_DEPENDENCIES, name, suite_rules.Dependency(lambda: None, dep.words))


def _run(pytester: pytest.Pytester, *args: str) -> pytest.RunResult:
    return pytester.runpytest("-p", "suite_rules", "-p", "no:cacheprovider", "-rA", *args)


@pytest.mark.parametrize("ci", ["true", "1", "yes"])
def test_ci_turns_dependency_skips_into_failures(pytester, monkeypatch, all_present, ci):
    monkeypatch.setenv("CI", ci)
    pytester.makepyfile(test_skipping=SKIPPING)
    result = _run(pytester)
    result.assert_outcomes(passed=1, failed=2, skipped=1)
    result.stdout.fnmatch_lines(["*missing core dependency (chromium)*", "*missing core dependency (pybullet)*"])
    assert result.ret == pytest.ExitCode.TESTS_FAILED


def test_ci_turns_a_module_level_skip_into_a_collection_error(pytester, monkeypatch, all_present):
    monkeypatch.setenv("CI", "true")
    pytester.makepyfile(test_import_skip=SKIPPED_AT_IMPORT)
    result = _run(pytester)
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*missing core dependency (llama_cpp)*"])
    assert result.ret != pytest.ExitCode.OK


RAY_MISSING = '''
import pytest

ray = pytest.importorskip("ray")  # as tests/bench/test_bench_ray.py does

def test_uses_ray():
    pass
'''


def test_ci_turns_a_missing_ray_into_a_failure_like_every_core_dependency(pytester, monkeypatch, all_present):
    """ray is in the dev extra: under CI the Ray backend's tests must not skip for want of it."""
    import sys

    assert "ray" in suite_rules.CORE_DEPENDENCIES
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` fails, as without the package
    monkeypatch.setenv("CI", "true")
    pytester.makepyfile(test_ray_missing=RAY_MISSING)
    result = _run(pytester)
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*missing core dependency (ray)*"])
    assert result.ret != pytest.ExitCode.OK
    monkeypatch.delenv("CI")
    _run(pytester).assert_outcomes(skipped=1)  # without CI it skips, as before
    assert suite_rules.dependency_named_in("an array of gray strays") is None


def test_the_ray_tests_skip_on_exactly_the_probe_of_a_core_dependency():
    """The skip tests/bench/test_bench_ray.py would give without ray names a core dependency."""
    reason = "could not import 'ray': No module named 'ray'"  # pytest.importorskip's words
    assert suite_rules.dependency_named_in(reason) == "ray"


@pytest.mark.parametrize("ci", [None, ""])
def test_without_ci_such_tests_skip(pytester, monkeypatch, all_present, ci):
    if ci is None:
        monkeypatch.delenv("CI", raising=False)
    else:
        monkeypatch.setenv("CI", ci)
    pytester.makepyfile(test_skipping=SKIPPING, test_import_skip=SKIPPED_AT_IMPORT)
    result = _run(pytester)
    result.assert_outcomes(passed=1, skipped=4)
    assert result.ret == pytest.ExitCode.OK


def test_ci_stops_at_session_start_without_chromium(pytester, monkeypatch, all_present, tmp_path):
    """The real Chromium probe, pointed at a path with no browser."""
    monkeypatch.setitem(suite_rules.CORE_DEPENDENCIES, "chromium",
                        suite_rules.Dependency(suite_rules._chromium, ("chromium",)))
    monkeypatch.setenv("ACTIVEINTENT_CHROMIUM", str(tmp_path / "no-chromium"))
    monkeypatch.setenv("CI", "true")
    pytester.makepyfile(test_fine="def test_fine():\n    pass\n")
    result = _run(pytester)
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stderr.fnmatch_lines(["*CI is set and core dependencies are missing*",
                                 f"*chromium: no executable browser at {tmp_path}*"])
    result.stdout.no_fnmatch_line("*passed*")  # nothing ran


def test_ci_stops_at_session_start_without_a_module(pytester, monkeypatch, all_present):
    monkeypatch.setitem(suite_rules.CORE_DEPENDENCIES, "pybullet", suite_rules.Dependency(
        lambda: suite_rules._importable("pybullet_not_installed_here"), ("pybullet",)))
    monkeypatch.setenv("CI", "true")
    pytester.makepyfile(test_fine="def test_fine():\n    pass\n")
    result = _run(pytester)
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result.stderr.fnmatch_lines(["*pybullet: cannot import pybullet_not_installed_here*"])


def test_header_and_slow_timeout(pytester, monkeypatch, all_present):
    monkeypatch.delenv("CI", raising=False)
    pytester.makeini("[pytest]\ntimeout = 300\nmarkers =\n    slow: slow\n")
    pytester.makepyfile(test_marks='''
import pytest

@pytest.mark.slow
def test_slow(request):
    assert request.node.get_closest_marker("timeout").args == (900,)

@pytest.mark.slow
@pytest.mark.timeout(30)
def test_own_timeout_wins(request):
    assert request.node.get_closest_marker("timeout").args == (30,)

def test_default(request):
    assert request.node.get_closest_marker("timeout") is None
''')
    result = _run(pytester)
    result.assert_outcomes(passed=3)
    for line in ("timeout: 300.0s", "timeouts: 300s per test, 900s for tests marked slow", "CI mode off*"):
        result.stdout.fnmatch_lines([line])


def test_this_run_has_the_default_timeout(pytestconfig):
    assert float(pytestconfig.getini("timeout")) == 300


# ---- isolation ----------------------------------------------------------------------------------

def test_caches_live_in_a_temporary_home(run_home):
    real_home = Path(pwd.getpwuid(os.getuid()).pw_dir).resolve()
    assert run_home.resolve().is_relative_to(Path(tempfile.gettempdir()).resolve())
    assert not run_home.resolve().is_relative_to(real_home) or real_home == Path("/")
    assert Path.home() == run_home
    for path in (default_cache_path(), default_model_dir(), hyp._cache_file(0, 6),
                 Path(os.environ["XDG_CACHE_HOME"])):
        assert path.is_relative_to(run_home), path


def test_no_fake_secret_left_in_the_environment():
    """tests/act sets a fake API key around each sandbox test; it must not outlive the test."""
    spec = importlib.util.spec_from_file_location("act_helpers_copy", Path(__file__).parent / "act" / "act_helpers.py")
    helpers = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(helpers)
    assert helpers.SECRET_NAME not in os.environ
    assert helpers.SECRET_VALUE not in os.environ.values()
