"""The study file: its schema, balanced assignment of participants to conditions (persisted
across restarts), participant IDs from the URL and the consent, without running an episode."""

from __future__ import annotations

import json
from collections import Counter

import pytest
from fastapi.testclient import TestClient

from activeintent.spec import RunSpec
from activeintent.web.server import create_app
from activeintent.web.session import StudyConfig
from activeintent.web.study import (
    Assigner,
    StudyFile,
    StudyFileError,
    button_order,
    check_pid,
    load_study,
)

CONDITIONS = [{"name": "pref-hidden", "method": "bayes-preference", "intention": "color-match"},
              {"name": "stop-hidden", "method": "bayes-stop", "intention": "color-match"},
              {"name": "stop-shown", "method": "bayes-stop", "intention": "color-match",
               "show_estimate": "after-answer"}]


def test_assignment_is_balanced_deterministic_and_survives_a_restart(tmp_path):
    names = [c["name"] for c in CONDITIONS]
    path = tmp_path / "assignment.json"
    first = Assigner(names, seed=7, path=path)
    got = [first.assign(f"P{i}").condition for i in range(10)]
    counts = Counter(got)
    assert max(counts.values()) - min(counts.values()) <= 1 and set(counts) == set(names)
    same = Assigner(names, seed=7)  # deterministic: the same seed gives the same sequence
    assert [same.assign(f"P{i}").condition for i in range(10)] == got
    # a returning participant keeps their condition and is not counted twice
    again = first.assign("P3")
    assert again.again and again.condition == got[3] and first.total == 10

    restarted = Assigner(names, seed=7, path=path)  # a new server on the same folder
    assert restarted.counts == dict(counts) and restarted.total == 10
    more = [restarted.assign(f"Q{i}").condition for i in range(5)]
    total = counts + Counter(more)
    assert sum(total.values()) == 15 and max(total.values()) - min(total.values()) <= 1
    assert json.loads(path.read_text())["participants"]["P3"]["condition"] == got[3]
    # the button order rotates within each condition: every order once before any twice
    slots = [restarted.assign(f"R{i}") for i in range(12)]
    orders = {tuple(button_order("preference", a.slot)) for a in slots if a.condition == "pref-hidden"}
    assert len(orders) == 4


def test_ties_go_by_the_seeded_order():
    names = [f"c{i}" for i in range(6)]
    one = Assigner(names, seed=1)
    assert [one.assign().condition for _ in range(6)] == one.tie_order  # all at 0, 1, …: seeded order
    firsts = {Assigner(names, seed=s).assign().condition for s in range(20)}
    assert len(firsts) > 1  # the seed decides, not the order in the file


def test_participant_ids_are_checked_with_a_clear_message():
    assert check_pid("5f8a0c2e9b1d4a3f6e7c8b90") == "5f8a0c2e9b1d4a3f6e7c8b90"
    for bad in ("", "a b", "x" * 65, "../etc", "P1<script>", "é"):
        with pytest.raises(ValueError, match="letters, digits"):
            check_pid(bad)


def _study(**extra) -> StudyFile:
    return StudyFile(consent="We ask you to teach a robot.\n\nYou may stop at any time.", completion_code="C0DE42",
                     redirect_url="https://example.org/done?cc=C0DE42", conditions=CONDITIONS, **extra)


def _app(tmp_path, study: StudyFile):
    config = StudyConfig(run=RunSpec.from_options(method="bayes-preference", budget=1), signal="preference",
                         out_dir=tmp_path)

    def never(*_):  # no episode is needed: every request here is refused before one starts
        raise AssertionError("a refused session must not start an episode")

    conditions = {c.name: (config, never) for c in study.conditions}
    return create_app(config, never, study=study, conditions=conditions)


def test_a_bad_or_missing_pid_and_no_consent_are_refused(tmp_path):
    client = TestClient(_app(tmp_path, _study()))
    public = client.get("/api/config").json()
    assert public["study"] and public["consent"].startswith("We ask") and public["require_pid"]
    assert "method" not in public and "signal" not in public  # not for participants
    res = client.post("/api/sessions", json={"pid": "bad id!", "consent": True})
    assert res.status_code == 422 and "participant ID 'bad id!' is not valid" in res.json()["error"]["message"]
    assert "letters, digits" in res.json()["error"]["message"]
    res = client.post("/api/sessions", json={"pid": "P1", "study_id": "x" * 65, "consent": True})
    assert res.status_code == 422 and "STUDY_ID" in res.json()["error"]["message"]
    res = client.post("/api/sessions", json={"consent": True})
    assert res.status_code == 422 and res.json()["error"]["code"] == "pid_required"
    res = client.post("/api/sessions", json={"pid": "P1"})
    assert res.status_code == 422 and res.json()["error"]["code"] == "consent_required"
    assert not (tmp_path / "assignment.json").exists()  # nobody was assigned


def test_the_study_file_names_what_is_wrong(tmp_path):
    good = tmp_path / "study.toml"
    good.write_text('consent = "Agree?"\ncompletion_code = "ABC"\n\n[[conditions]]\nname = "a"\n'
                    'method = "bayes-stop"\nintention = "color-match"\n')
    study = load_study(good)
    assert study.completion_code == "ABC" and study.conditions[0].show_estimate == "hidden"
    with pytest.raises(ValueError, match="unknown condition 'b'.*: a"):
        study.condition("b")
    cases = {
        "m.json": ({"consent": "x", "conditions": [{"name": "a", "method": "clicks"}]}, "bayes-preference"),
        "r.json": ({"consent": "x", "conditions": [{"name": "a", "method": "bayes-stop", "intention": "nope"}]},
                   "color-match"),
        "d.json": ({"consent": "x", "conditions": [{"name": "a", "method": "bayes-stop"}] * 2}, "more than once: a"),
        "u.json": ({"consent": "x", "conditions": [{"name": "a", "method": "bayes-stop"}],
                    "redirect_url": "javascript:alert(1)"}, "redirect_url"),
    }
    for name, (data, message) in cases.items():
        (tmp_path / name).write_text(json.dumps(data))
        with pytest.raises(StudyFileError, match=message):
            load_study(tmp_path / name)
    (tmp_path / "s.yaml").write_text("x")
    with pytest.raises(StudyFileError, match=".json or .toml"):
        load_study(tmp_path / "s.yaml")


def test_the_final_guess_reports_the_learners_expected_success_when_no_belief_names_it():
    from types import SimpleNamespace

    from activeintent.web.session import guess_of

    final = SimpleNamespace(z="Put each block in the bowl of the same colour.", why={"expected_success": 0.83})
    g = guess_of(final, answers=2, belief_top=[["color-match", 0.6]])  # snapshots name rules, z is a description
    assert g.confidence == 0.83 and g.kind == "expected_success" and "expected probability" in g.basis
    none = guess_of(SimpleNamespace(z="z", why={}), answers=2)
    assert none.confidence is None and none.kind is None
