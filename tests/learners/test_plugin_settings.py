"""A learner's setting is one field of its config class: a plug-in that declares a new one finds it
in `run --help`, in the checked spec, in the records and in bench's resume check, with no file of
the package changed."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from typer.testing import CliRunner

from activeintent.bench.runner import run_bench
from activeintent.bench.work import BenchConfig
from activeintent.cli import app
from activeintent.registry import load_plugin
from activeintent.runner import build_episode, check_spec
from activeintent.spec import RunSpec

PLUGIN = '''
from pydantic import BaseModel, ConfigDict, Field

from activeintent.learners.bayes.learner import BayesConfig, BayesLearner
from activeintent.learners.registry import METHODS, Method


class PatientSettings(BaseModel):
    model_config = ConfigDict(extra="forbid")

    patience: int = Field(3, ge=1, le=9, description="Answers heard before it designs its own scenes")


def build(ctx):
    learner = BayesLearner("stop", rng=ctx.learner_seed, config=BayesConfig(n_scenes=ctx.settings.patience))
    learner.name = "patient-stop"
    return learner


METHODS.register("patient-stop", lambda: Method("stop", False, build, "test: a setting of its own",
                                                settings=PatientSettings))
'''


@pytest.fixture(scope="module")
def plugin(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("plugin") / "patient.py"
    path.write_text(PLUGIN)
    return str(path)


def test_a_plugins_setting_is_an_option_of_run_with_its_help(plugin):
    shown = subprocess.run([sys.executable, "-m", "activeintent.cli", "run", "--plugin", plugin, "--help"],
                           capture_output=True, text=True, env={**os.environ, "COLUMNS": "200"}, timeout=300)
    assert shown.returncode == 0, shown.stderr
    assert "--patience" in shown.stdout and "Answers heard before it designs" in shown.stdout
    assert "patient-stop" in shown.stdout  # which methods take it
    load_plugin(plugin)
    assert "--patience" in CliRunner().invoke(app, ["bench", "--help"], env={"COLUMNS": "200"}).output


def test_the_setting_is_validated_by_its_class_and_recorded_as_it_ran(plugin, tmp_path):
    load_plugin(plugin)
    spec = RunSpec.from_options(method="patient-stop", intention="stack", env="symbolic", llm="none", budget=1,
                                test_scenes=2, test_pool=0, video="none", patience=5, plugin=[plugin])
    assert check_spec(spec).learner.settings == {"patience": 5}
    with pytest.raises(ValueError, match="--patience: Input should be less than or equal to 9"):
        check_spec(spec.with_options(patience=12))
    with pytest.raises(ValueError, match="--patience: bayes-stop has no such setting"):
        check_spec(spec.with_options(method="bayes-stop"))
    build_episode(spec, tmp_path).run()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["config"]["spec"]["learner"] == {"method": "patient-stop", "settings": {"patience": 5}}


def test_run_takes_the_setting_from_the_command_line(plugin, tmp_path):
    res = CliRunner().invoke(app, ["run", "--plugin", plugin, "--method", "patient-stop", "--patience", "4",
                                   "--intention", "stack", "--env", "symbolic", "--llm", "none", "--budget", "1",
                                   "--test-scenes", "2", "--test-pool", "0", "--video", "none",
                                   "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["config"]["spec"]["learner"]["settings"] == {"patience": 4}


def test_bench_gives_the_setting_to_its_method_and_resumes_only_with_the_same(plugin, tmp_path):
    load_plugin(plugin)

    def bench(patience: int) -> BenchConfig:
        run = RunSpec.from_options(budget=1, test_scenes=2, test_pool=0, llm="none", env="symbolic", video="none",
                                   patience=patience, plugin=[plugin])
        return BenchConfig(methods=["patient-stop", "zero-signal"], intentions=["stack"], trials=1, run=run)

    records = run_bench(bench(2), tmp_path)
    settings = {r["method"]: r["config"]["spec"]["learner"]["settings"] for r in records}
    assert settings == {"patient-stop": {"patience": 2}, "zero-signal": {"prior": "length", "scenes": "sampled"}}
    assert len(run_bench(bench(2), tmp_path)) == 2  # the same settings: resumed, nothing to run
    with pytest.raises(ValueError, match="other settings.*patience"):
        run_bench(bench(3), tmp_path)
