"""bench.json, versioned: written with its format, read in any format it had (a format-1 file's
missing options take the values they had in effect), a newer one refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from activeintent.bench.legacy import BENCH_FORMAT
from activeintent.bench.work import BenchConfig, read_bench_config, write_bench_config
from activeintent.runner import RunSpec

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"


def test_written_with_its_format_and_read_back(tmp_path):
    options = BenchConfig(methods=["bayes-stop"], intentions=["stack"], trials=3, run=RunSpec.from_options(video="none"))
    write_bench_config(options, tmp_path / "bench.json")
    assert json.loads((tmp_path / "bench.json").read_text())["format"] == BENCH_FORMAT
    assert read_bench_config(tmp_path / "bench.json") == options


def test_a_format_1_file_gets_the_options_in_effect_then(tmp_path):
    data = json.loads(BenchConfig(methods=["mllm"]).model_dump_json())
    data["run"] = RunSpec.from_options(video="none", epsilon=1.5).options()  # flat, as format 1 wrote it
    data["run"].pop("test_pool")
    (tmp_path / "bench.json").write_text(json.dumps(data))  # no "format": format 1
    run = read_bench_config(tmp_path / "bench.json").run
    settings = run.learner.settings
    assert (settings["variant"], settings["early_threshold"], run.protocol.test_pool) == ("structured", 1.5, 0)


def test_a_format_3_file_with_the_learners_section_flat_reads_as_the_same_spec(tmp_path):
    spec = RunSpec.from_options(video="none", budget=7, env="symbolic", llm="none", executor="parse",
                                prior="uniform", epsilon=1.0, scenes="sampled", language=1)
    run = spec.model_dump(mode="json", exclude={"act"})
    run["learner"] = {"method": "bayes-stop", "prior": "uniform", "epsilon": 1.0, "executor": "parse"}
    data = {**json.loads(BenchConfig(methods=["bayes-stop"]).model_dump_json()), "format": 3, "run": run}
    (tmp_path / "bench.json").write_text(json.dumps(data))
    assert read_bench_config(tmp_path / "bench.json").run == spec  # scenes, language: the values then


def test_a_format_2_file_in_flat_option_names_reads_as_the_same_spec(tmp_path):
    spec = RunSpec.from_options(video="none", budget=7, env="symbolic", llm="none", user="paper", prior="uniform")
    data = {**json.loads(BenchConfig(methods=["bayes-stop"]).model_dump_json()), "format": 2, "run": spec.options()}
    (tmp_path / "bench.json").write_text(json.dumps(data))
    # settings added since format 2: the values that ran then
    assert read_bench_config(tmp_path / "bench.json").run == spec.with_options(scenes="sampled", language=1)


def test_a_newer_format_is_refused(tmp_path):
    (tmp_path / "bench.json").write_text(json.dumps({"format": BENCH_FORMAT + 1, "methods": ["bayes-stop"]}))
    with pytest.raises(ValueError, match="update activeintent"):
        read_bench_config(tmp_path / "bench.json")


def test_every_committed_folder_reads():
    folders = sorted(p for p in RESULTS.glob("*/bench.json"))
    assert len(folders) >= 10
    for path in folders:
        assert read_bench_config(path).methods, path
