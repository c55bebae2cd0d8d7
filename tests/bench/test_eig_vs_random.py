"""EIG questions beat random questions on the same episodes (docs/results/eig-vs-random: paper and
dev suites, exact users, 8 trials): the paired 95 % interval of the difference in area under
success@k lies above 0 (for preference questions; for stop questions it does not yet: a marked
finding), and a sample re-run from the code agrees with the folder (so a learner that asked at
random would fail here)."""

from __future__ import annotations

from pathlib import Path

import pytest

from activeintent.bench.report import paired_difference
from activeintent.bench.verify import verify
from activeintent.results import read_results
from activeintent.suites import suite

FOLDER = Path(__file__).resolve().parents[2] / "docs" / "results" / "eig-vs-random"


@pytest.fixture(scope="module")
def records() -> list[dict]:
    return [r for r in read_results(FOLDER / "results.jsonl") if not r.get("error")]


def test_the_folder_holds_the_protocol_the_claim_names(records):
    assert {r["user_preset"] for r in records} == {"exact"} and {r["budget"] for r in records} == {5}
    assert {r["intention"] for r in records} == set(suite("paper")) | set(suite("dev"))
    assert {r["trial"] for r in records} >= set(range(8))


# A finding, not a loosened test: with exact users the stop learner's EIG questions are not
# measurably better than random ones on these suites (+0.015 [-0.015, +0.045], n = 112, at
# 3b8da2a); the fix belongs in the learner (issue "Questions worth a person's answer"). strict:
# this test fails as soon as the claim holds, so the mark cannot outlive the finding.
STOP_FINDING = pytest.mark.xfail(strict=True, reason="EIG stop questions do not yet beat random ones (exact users)")


@pytest.mark.parametrize("eig,random", [pytest.param("bayes-stop", "random-query", marks=STOP_FINDING),
                                        ("bayes-preference", "random-query-preference")])
def test_eig_questions_beat_random_ones_on_the_same_episodes(records, eig, random):
    d = paired_difference(records, eig, random)
    assert d is not None and d["n"] >= 8 * 14
    assert d["lo"] > 0, f"{eig} − {random}: {d}"


def test_the_committed_comparison_comes_out_of_the_code():
    assert verify(FOLDER, sample=4) == []  # one episode of each of the four methods
