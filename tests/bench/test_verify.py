"""Published numbers come out of the code: a sample of the committed paper-suite results is
re-run from its recorded settings and must agree line for line."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from activeintent.bench.verify import verify

PAPER = Path(__file__).resolve().parents[2] / "docs" / "results" / "paper"


def test_committed_paper_results_come_out_of_the_code():
    assert verify(PAPER, sample=3, methods=["zero-signal", "bayes-stop"]) == []


def test_a_changed_line_is_reported(tmp_path):
    folder = tmp_path / "paper"
    folder.mkdir()
    shutil.copy(PAPER / "bench.json", folder / "bench.json")
    lines = [json.loads(x) for x in (PAPER / "results.jsonl").read_text().splitlines()]
    first = min((r for r in lines if r["method"] == "zero-signal"), key=lambda r: (r["trial"], r["intention"]))
    first["success_at"] = [1.0] * len(first["success_at"])  # a flattering edit
    (folder / "results.jsonl").write_text(json.dumps(first) + "\n")
    (diff,) = verify(folder, sample=1)
    assert diff["method"] == "zero-signal" and "success_at" in diff["changed"]
