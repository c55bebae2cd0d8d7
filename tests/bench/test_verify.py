"""Published numbers come out of the code: every committed results folder is either re-run from
its recorded settings in a sample that covers every method (the paper suite in the fast suite,
the others marked slow, which CI runs) or says in NOT-VERIFIED.md why it cannot be."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from activeintent.bench.checks import Plan
from activeintent.bench.verify import NOT_VERIFIED, StaleFolder, differences, sample_records, verify
from activeintent.bench.work import read_bench_config
from activeintent.protocol import FORMAT_VERSION
from activeintent.results import load_results, read_results
from activeintent.spec import RunSpec

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"
PAPER = RESULTS / "paper"
FAST = {"paper"}  # every method re-run in the fast suite; every other headline folder by a slow test
# The method re-run from each headline folder in CI (one episode: the sample covers every product
# learner across the folders); `bench-verify --all` re-runs one episode of every method of every
# folder, experiments' included, before a release.
CI_METHOD = {"dev": "lang-stop", "dev-lang2": "lang-stop", "heldout-freeze": "lang-preference", "peer": "reward-stop",
             "truth-goals-stop": "lang-stop", "truth-goals-preference": "lang-preference",
             "truth-goals-exact": "zero-signal", "library": "bayes-preference", "heldout": "bayes-stop",
             "eig-vs-random": "random-query-preference", "paper-physics": "bayes-stop"}
NOT_BENCH = {"perf-lang": "benchmark timings (perf-bench JSON), not results",
             "web-wait": "the web study's waits (web-bench JSON), not results",
             "coverage": "coverage of the goal language (re-run by tests/bench/test_coverage.py)",
             "redesign-equivalence": "its own replay scripts and README",
             "clairvoyant-bound": "a diagnostic's rows (examples/clairvoyant_bound.py reads the hidden intention), "
                                  "not a method's results"}
EXPERIMENTS = RESULTS.parents[1] / "experiments"


def bench_folders() -> list[str]:
    return sorted(p.name for p in RESULTS.iterdir() if (p / "bench.json").is_file() and not (p / NOT_VERIFIED).is_file())


def test_every_results_folder_is_verified_or_says_why_not():
    for folder in [*RESULTS.iterdir(), *EXPERIMENTS.glob("*/results/*")]:
        if folder.is_file():  # the files beside the folders: the log of held-out runs, the index
            assert folder.name in ("HELDOUT_RUNS.md", "README.md"), folder
            continue
        if folder.name in NOT_BENCH:
            assert not (folder / "results.jsonl").exists()
            continue
        assert (folder / "bench.json").is_file(), folder
        plan = Plan(read_bench_config(folder / "bench.json"))
        loaded = load_results(folder / "results.jsonl", plan).set_aside_duplicates()
        assert loaded.rejected == [], folder.name  # every record belongs to its folder (bench/checks.py)
        if (folder / NOT_VERIFIED).is_file():
            with pytest.raises(StaleFolder):
                verify(folder, sample=1)
            continue
        records = loaded.records
        assert records and all(r["format"] == FORMAT_VERSION for r in records), folder.name
        made = {(r["provenance"]["commit"], r["provenance"]["dirty"]) for r in records}
        assert all(commit and dirty is False for commit, dirty in made), f"{folder.name}: made by {made}"


@pytest.mark.parametrize("name", [pytest.param(n, marks=[] if n in FAST else [pytest.mark.slow]) for n in bench_folders()])
def test_committed_results_come_out_of_the_code(name):
    folder = RESULTS / name
    methods = {r["method"] for r in read_results(folder / "results.jsonl") if not r.get("error")}
    if name in FAST:
        assert verify(folder, sample=len(methods)) == []  # one episode of every method
    else:
        chosen = CI_METHOD.get(name, sorted(methods)[0])
        assert chosen in methods, f"{name} has no {chosen} records"
        assert verify(folder, sample=1, methods=[chosen]) == []


def test_all_means_every_committed_folder_headline_and_experiments():
    from activeintent.bench.verify import committed_folders

    found = committed_folders(RESULTS.parents[1])
    assert set(bench_folders()) <= {f.name for f in found if f.parent == RESULTS}
    assert any(f.parent.parent.parent == EXPERIMENTS for f in found)


def test_records_of_older_options_are_read_with_the_value_they_ran_with():
    from activeintent.bench.legacy import migrated

    old = {"success": 1.0, "prior": "length", "variant": "faithful",
           "config": {"options": {"method": "lang-stop", "prior": "fitted", "epsilon": 2.0,
                                  "plugins": ["examples/x.py"]}}}
    spec = RunSpec.from_options(method="lang-stop", prior="fitted", scenes="sampled", language=1)
    new = {"success": 1.0, "config": {"spec": spec.model_dump(mode="json", exclude={"plugins"})}}
    assert differences(migrated(old), migrated(new)) == {}  # the old shape read as the new
    belief = {**new, "config": {"spec": spec.with_options(scenes="belief").model_dump(mode="json", exclude={"plugins"})}}
    assert set(differences(migrated(old), migrated(belief))) == {"config.spec.learner.settings.scenes"}
    assert migrated(new) == new


def test_the_sample_covers_every_method_before_any_twice():
    records = [{"method": m, "intention": i, "trial": t} for t in range(3) for i in "ab" for m in ("x", "y", "z")]
    picked = sample_records(records, 4)
    assert {r["method"] for r in picked[:3]} == {"x", "y", "z"} and picked[3]["method"] == "x"
    assert all(r["trial"] == 0 for r in picked)


def test_whole_records_are_compared_but_not_timings_or_provenance():
    a = {"success": 1.0, "learner_stats": {"top": [["x", 0.9]]}, "wall_s": 1.0, "provenance": {"commit": "a"}}
    b = {"success": 1.0, "learner_stats": {"top": [["y", 0.9]]}, "wall_s": 2.0, "provenance": {"commit": "b"}}
    assert differences(a, b) == {"learner_stats.top": ([["x", 0.9]], [["y", 0.9]])}


def test_final_z_is_compared_once_records_say_which_scene_it_comes_from():
    """Before ``final_scene`` was recorded, final_z came from test scene 0: such a record cannot
    differ in the field's new meaning; every record that has final_scene is compared on it."""
    old = {"success": 1.0, "final_z": "on scene 0", "final_goal": "g0"}
    new = {"success": 1.0, "final_z": "on scene 2", "final_goal": "g2", "final_scene": 2}
    assert differences(old, new) == {}
    assert set(differences({**new, "final_z": "other"}, new)) == {"final_z"}
    assert set(differences({**new, "final_scene": 1}, new)) == {"final_scene"}


def test_a_changed_line_is_reported(tmp_path):
    folder = tmp_path / "paper"
    folder.mkdir()
    shutil.copy(PAPER / "bench.json", folder / "bench.json")
    lines = [json.loads(x) for x in (PAPER / "results.jsonl").read_text().splitlines()]
    first = min((r for r in lines if r["method"] == "zero-signal"), key=lambda r: (r["trial"], r["intention"]))
    first["success_at"] = [1.0] * len(first["success_at"])  # a flattering edit, consistent with itself
    first["success"] = 1.0
    (folder / "results.jsonl").write_text(json.dumps(first) + "\n")
    (diff,) = verify(folder, sample=1)
    assert diff["method"] == "zero-signal" and "success_at" in diff["changed"]


def test_a_folder_of_an_older_format_is_refused_not_compared(tmp_path):
    folder = tmp_path / "old"
    folder.mkdir()
    shutil.copy(PAPER / "bench.json", folder / "bench.json")
    line = json.loads((PAPER / "results.jsonl").read_text().splitlines()[0])
    (folder / "results.jsonl").write_text(json.dumps({**line, "format": FORMAT_VERSION - 1}) + "\n")
    with pytest.raises(StaleFolder, match="regenerate"):
        verify(folder, sample=1)


def test_the_results_index_names_every_folder():
    index = (RESULTS / "README.md").read_text()
    folders = [p for p in [*RESULTS.iterdir(), *EXPERIMENTS.glob("*/results/*")] if p.is_dir()]
    missing = [p.name for p in folders if f"[{p.name}]" not in index and f"`{p.name}`" not in index]
    assert folders and not missing, missing
