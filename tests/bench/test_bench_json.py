"""bench.json, versioned: written with its format, read in any format it had (a format-1 file's
missing options take the values they had in effect), a newer one refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from activeintent.bench.work import (
    BENCH_FORMAT,
    BenchOptions,
    read_bench_options,
    write_bench_options,
)
from activeintent.runner import RunOptions

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"


def test_written_with_its_format_and_read_back(tmp_path):
    options = BenchOptions(methods=["bayes-stop"], intentions=["stack"], trials=3, run=RunOptions(video="none"))
    write_bench_options(options, tmp_path / "bench.json")
    assert json.loads((tmp_path / "bench.json").read_text())["format"] == BENCH_FORMAT
    assert read_bench_options(tmp_path / "bench.json") == options


def test_a_format_1_file_gets_the_options_in_effect_then(tmp_path):
    data = json.loads(BenchOptions(methods=["mllm"], run=RunOptions(video="none", epsilon=1.5)).model_dump_json())
    for key in ("variant", "early_threshold", "test_pool"):
        data["run"].pop(key)
    (tmp_path / "bench.json").write_text(json.dumps(data))  # no "format": format 1
    run = read_bench_options(tmp_path / "bench.json").run
    assert (run.variant, run.early_threshold, run.test_pool) == ("structured", 1.5, 0)


def test_a_newer_format_is_refused(tmp_path):
    (tmp_path / "bench.json").write_text(json.dumps({"format": BENCH_FORMAT + 1, "methods": ["bayes-stop"]}))
    with pytest.raises(ValueError, match="update activeintent"):
        read_bench_options(tmp_path / "bench.json")


def test_every_committed_folder_reads():
    folders = sorted(p for p in RESULTS.glob("*/bench.json"))
    assert len(folders) >= 10
    for path in folders:
        assert read_bench_options(path).methods, path
