"""What a study needs besides the rounds: the design (assigned or free rule) and what is scored,
whether and when the learner's guess is shown, the end-of-session questionnaire, and the
study-wide export. Fast unit tests first, then API tests against a live server."""

from __future__ import annotations

import csv
import json
import time
from pathlib import Path
from types import SimpleNamespace

import httpx
import pytest
from typer.testing import CliRunner

from activeintent.cli import app
from activeintent.spec import RunSpec
from activeintent.web.export import collect_sessions, session_record, write_table
from activeintent.web.session import StudyConfig, guess_of, scene_legend, study_summary


def stop_study(budget: int, **user) -> StudyConfig:
    return StudyConfig(run=RunSpec.from_options(method="bayes-stop", budget=budget, **user), signal="stop")


# -- unit tests (no server) ---------------------------------------------------------------------
def test_study_defaults_free_rule_hidden_guess_and_readable_videos():
    config = stop_study(2)
    assert config.design == "free-rule" and config.intention_name is None and config.intention_description is None
    assert config.show_estimate == "hidden"
    assert config.video_size == (800, 600)  # every block at least 40 px (tests/sim/test_camera.py)
    assert json.loads(config.model_dump_json())["design"] == "free-rule"  # recorded in session.json
    assigned = stop_study(2, intention="color-match")
    assert assigned.design == "assigned-rule" and assigned.intention_name == "color-match"
    assert assigned.intention_description == "Put each block in the bowl of the same colour."
    with pytest.raises(ValueError):
        StudyConfig(run=RunSpec.from_options(method="bayes-stop", budget=2), signal="stop", show_estimate="sometimes")


def _summary() -> dict:
    return {"method": "bayes-stop", "intention": "color-match", "success": 0.5, "success_at": [0.0, 0.5],
            "success_physics": 1.0, "physics_disagreements": 0, "test_excluded": 1, "final_z": "z",
            "tests": [{"scene": ["red block"], "feasible": True, "success": True, "success_physics": True,
                       "z": "z"}]}


def test_a_free_rule_summary_scores_nothing_an_assigned_one_keeps_its_score():
    free = study_summary(_summary(), stop_study(1))
    assert free["success"] is None and free["success_basis"] == "none" and free["design"] == "free-rule"
    assert free["intention"] is None and free["success_at"] == [None, None]
    assert free["success_physics"] is None and free["test_excluded"] is None
    assert free["tests"][0]["success"] is None and free["tests"][0]["feasible"] is None
    assert free["tests"][0]["z"] == "z" and free["final_z"] == "z"  # the learner's side stays
    assert "color-match" not in json.dumps(free)
    assigned = study_summary(_summary(), stop_study(1, intention="color-match"))
    assert assigned["success"] == 0.5 and assigned["success_basis"] == "assigned-rule"


def test_a_guess_carries_the_learners_belief_where_it_has_one():
    bayes = SimpleNamespace(z="rule one", why={"belief_before": {"top": [("rule one", 0.42), ("rule two", 0.3)]}})
    g = guess_of(bayes, answers=2)
    assert g.z == "rule one" and g.confidence == 0.42 and g.answers == 2 and "posterior" in g.basis
    final = SimpleNamespace(z="rule two", why={"expected_success": 0.9})
    assert guess_of(final, answers=3, belief_top=[["rule one", 0.5], ["rule two", 0.25]]).confidence == 0.25
    model = SimpleNamespace(z="something", why={"reasoning": "…"})
    assert guess_of(model, answers=1).confidence is None and guess_of(model, answers=1).basis is None


def test_the_legend_names_every_object_with_its_colour():
    legend = scene_legend(["pink block", "red bowl", "brown block"])
    assert [o["name"] for o in legend] == ["pink block", "red bowl", "brown block"]
    assert [o["kind"] for o in legend] == ["block", "bowl", "block"]
    assert all(o["hex"].startswith("#") and len(o["hex"]) == 7 for o in legend)
    assert len({o["hex"] for o in legend}) == 3


def _fake_session(root: Path, sid: str, created: float, design: str, rule: str | None,
                  questionnaire: dict | None) -> Path:
    folder = root / sid
    folder.mkdir(parents=True)
    study = {"method": "bayes-preference", "signal": "preference", "rounds": 2, "design": design,
             "intention": rule, "intention_description": "Put each block in the bowl of the same colour."
             if rule else None, "show_estimate": "hidden", "video_size": [480, 480]}
    (folder / "session.json").write_text(json.dumps({
        "id": sid, "seed": 0, "participant": "=HYPERLINK(\"x\")" if questionnaire else "P2", "created": created,
        "design": design, "show_estimate": "hidden", "status": "finished", "ended": created + 60, "error": None,
        "study": study}))
    rounds = [{"round": 1, "answer": {"signal": "preference", "new_scene": False, "choice": "A"}, "z": "g1",
               "counted": True},
              {"round": 2, "answer": {"signal": "preference", "new_scene": True, "choice": None}, "z": "g2",
               "counted": True}]
    (folder / "rounds.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rounds))
    events = [{"source": "server", "type": "round_presented", "round": 1, "server_ts": created + 1},
              {"source": "server", "type": "answer", "round": 1, "server_ts": created + 4.5},
              {"source": "server", "type": "round_presented", "round": 2, "server_ts": created + 6},
              {"source": "server", "type": "answer", "round": 2, "server_ts": created + 8},
              # the page's record of two stalls in round 2 (playback waited for frames)
              {"source": "client", "type": "video_stall", "round": 2, "client_ts": created + 7,
               "data": {"video": "A", "at": 0.0, "seconds": 1.25, "how": "resumed"}},
              {"source": "client", "type": "video_stall", "round": 2, "client_ts": created + 7.5,
               "data": {"video": "B", "at": 2.1, "seconds": 0.5, "how": "resumed"}}]
    (folder / "events.jsonl").write_text("".join(json.dumps(e) + "\n" for e in events) + '{"torn')
    (folder / "summary.json").write_text(json.dumps({"success": 1.0, "success_basis": "assigned-rule" if rule else
                                                     "none", "signals_used": 2, "final_z": "final guess"}))
    if questionnaire is not None:
        (folder / "questionnaire.json").write_text(json.dumps({**questionnaire, "submitted": created + 70}))
    return folder


def test_the_export_has_one_row_per_session_and_neutralises_formulas(tmp_path):
    out = tmp_path / "study"
    _fake_session(out, "b" * 16, 2000.0, "free-rule", None, None)
    _fake_session(out, "a" * 16, 1000.0, "assigned-rule", "color-match",
                  {"final_attempt": "partly", "rule": "=1+1 colours match", "comments": "nice\nrobot"})
    (out / "not-a-session").mkdir()
    records, skipped = collect_sessions(out)
    assert skipped == [] and [r["session"] for r in records] == ["a" * 16, "b" * 16]  # by start time
    first, second = records
    assert first["design"] == "assigned-rule" and first["intention"] == "color-match" and first["success"] == 1.0
    assert second["design"] == "free-rule" and second["success"] is None and second["success_basis"] == "none"
    assert [r["answer"] for r in first["rounds"]] == ["A", "new_scene"]
    assert [r["response_s"] for r in first["rounds"]] == [3.5, 2.0] and first["answer_seconds_total"] == 5.5
    assert first["session_seconds"] == 60 and first["questionnaire_final_attempt"] == "partly"
    assert [(r["stalls"], r["stall_s"]) for r in first["rounds"]] == [(0, 0.0), (2, 1.75)]
    assert first["stalls_total"] == 2 and first["stall_seconds_total"] == 1.75

    table = tmp_path / "study.csv"
    write_table(records, table)
    rows = list(csv.DictReader(table.open(newline="")))
    assert len(rows) == 2 and rows[0]["round2_answer"] == "new_scene" and rows[0]["round1_response_s"] == "3.5"
    assert rows[0]["round2_stalls"] == "2" and rows[0]["round2_stall_s"] == "1.75"
    assert rows[0]["questionnaire_rule"] == "'=1+1 colours match"  # shown as text, not run
    assert rows[0]["participant"].startswith("'=") and rows[0]["questionnaire_comments"] == "nice\nrobot"
    assert rows[1]["success"] == "" and rows[1]["questionnaire_rule"] == ""
    lines = tmp_path / "study.jsonl"
    write_table(records, lines)
    back = [json.loads(x) for x in lines.read_text().splitlines()]
    assert back[0]["questionnaire_rule"] == "=1+1 colours match"  # the JSONL keeps the text as typed
    assert back[0]["rounds"][0]["h"]["choice"] == "A"

    res = CliRunner().invoke(app, ["study-export", str(out), "--to", str(tmp_path / "x.txt")])
    assert res.exit_code != 0 and ".csv or .jsonl" in res.output
    res = CliRunner().invoke(app, ["study-export", str(out), "--to", str(tmp_path / "cli.csv")])
    assert res.exit_code == 0 and "2 sessions (1 with a questionnaire)" in res.output, res.output
    broken = out / ("c" * 16)
    broken.mkdir()
    (broken / "session.json").write_text("{not json")
    records, skipped = collect_sessions(out)
    assert len(records) == 2 and [p.name for p, _ in skipped] == ["c" * 16]
    with pytest.raises(ValueError):
        session_record(broken)


# -- against a live server ------------------------------------------------------------------------
def _wait(predicate, timeout: float = 180.0, what: str = "condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def _waiting(url: str, sid: str, n: int) -> dict:
    def ready():
        s = httpx.get(f"{url}/api/sessions/{sid}").json()
        assert s["status"] not in ("failed", "cancelled"), s["error"]
        return s if s["status"] == "waiting-for-answer" and s["question"]["round"] == n else None

    return _wait(ready, what=f"round {n}")


@pytest.mark.slow
def test_free_rule_session_questionnaire_and_guess_shown_always(live_server, http):
    srv = live_server("bayes-stop", rounds=2, seed=2, video_size=(64, 64), show_estimate="always")
    api = f"{srv.url}/api"
    config = httpx.get(f"{api}/config").json()
    assert config["design"] == "free-rule" and "intention" not in config and "method" not in config
    assert config["intention_description"] is None and config["show_estimate"] == "always"
    sid = http.post(f"{api}/sessions", json={"participant": "P-free"}).json()["id"]
    folder = srv.session_dir(sid)
    q = f"{api}/sessions/{sid}/questionnaire"

    state = _waiting(srv.url, sid, 1)
    assert state["estimate"] is None  # never a guess before the first answer, whatever the study says
    assert [o["name"] for o in state["question"]["legend"]] == state["question"]["scene"]
    assert state["questionnaire"] == {"open": False, "submitted": False, "asks_final_attempt": False}
    early = http.post(q, json={"final_attempt": "yes", "rule": "mine"})
    assert early.status_code == 409 and "after the robot's final attempt" in early.json()["error"]["message"]
    http.post(f"{api}/sessions/{sid}/answer", json={"kind": "stop", "round": 1, "action": "no_stop"})
    state = _waiting(srv.url, sid, 2)
    guess = state["estimate"]
    assert guess["answers"] == 1 and guess["z"] and 0 <= guess["confidence"] <= 1  # a Bayesian learner's belief
    http.post(f"{api}/sessions/{sid}/answer", json={"kind": "stop", "round": 2, "action": "new_scene"})
    session = srv.manager.get(sid)
    assert session.join(300) and session.status == "finished", session.error

    summary = json.loads((folder / "summary.json").read_text())
    assert summary["success"] is None and summary["success_basis"] == "none" and summary["intention"] is None
    assert all(t["success"] is None for t in summary["tests"]) and set(summary["success_at"]) == {None}
    result = httpx.get(f"{api}/sessions/{sid}/result").json()  # the participant's view: no condition
    assert result == {"budget": 2, "signals_used": 2, "rounds_used": summary["rounds_used"],
                      "answers": summary["answers"], "design": "free-rule"}
    state = httpx.get(f"{api}/sessions/{sid}").json()
    assert state["success"] is None and state["success_basis"] == "none"
    assert state["estimate"]["answers"] == 2 and state["final_video"] and state["final_legend"]
    assert state["questionnaire"] == {"open": True, "submitted": False, "asks_final_attempt": True}
    info = json.loads((folder / "session.json").read_text())
    assert info["status"] == "finished" and info["show_estimate"] == "always" and info["design"] == "free-rule"
    assert info["ended"] >= info["created"]
    events = [json.loads(x) for x in (folder / "events.jsonl").read_text().splitlines()]
    presented = [e for e in events if e["type"] == "round_presented"]
    assert [e["estimate_shown"] for e in presented] == [False, True]  # what the participant saw, per round
    assert all(e["estimate"] and 0 <= e["confidence"] <= 1 for e in presented)

    # the questions about the final attempt open only once the server saw its video end
    unwatched = http.post(q, json={"final_attempt": "yes", "rule": "mine"})
    assert unwatched.status_code == 409 and unwatched.json()["error"]["code"] == "final_video_not_watched"
    assert not (folder / "questionnaire.json").exists()
    final = f"{api}/sessions/{sid}/final-video"
    assert http.post(final, json={"event": "replay"}).status_code == 409  # a replay only after the end
    assert http.post(final, json={"event": "ready", "media_time": 0}).status_code == 200
    viewing = http.post(final, json={"event": "ended", "media_time": 3.2}).json()["viewing"]
    assert viewing["ended"] >= viewing["ready"] and viewing["replays"] == 0

    before = sorted(p.name for p in folder.iterdir())
    bad = [
        ({"final_attempt": "yes", "rule": "mine", "admin": True}, "invalid_request", "admin"),
        ({"final_attempt": "yes"}, "invalid_request", "rule: Field required"),
        ({"final_attempt": "yes", "rule": "   "}, "invalid_request", "must say something"),
        ({"final_attempt": "yes", "rule": "x" * 2001}, "invalid_request", "2000"),
        ({"final_attempt": "maybe", "rule": "mine"}, "invalid_request", "'yes', 'partly' or 'no'"),
        ({"final_attempt": "no", "rule": "a\x00b"}, "invalid_request", "printable"),
        ({"final_attempt": "no", "rule": "ok", "comments": "c" * 4001}, "invalid_request", "4000"),
        ({"rule": "mine"}, "invalid_answer", "final_attempt is required"),
    ]
    for body, code, message in bad:
        res = http.post(q, json=body)
        assert res.status_code == 422, (body, res.text)
        assert res.json()["error"]["code"] == code and message in res.json()["error"]["message"], res.json()
    assert sorted(p.name for p in folder.iterdir()) == before, "a refused questionnaire was saved"

    ok = http.post(q, json={"final_attempt": "partly", "rule": "  Blocks near bowls\nof their colour ",
                             "comments": "", "client_ts": 1.7e9})
    assert ok.status_code == 201, ok.text
    saved = json.loads((folder / "questionnaire.json").read_text())
    assert saved["final_attempt"] == "partly" and saved["rule"] == "Blocks near bowls\nof their colour"
    assert saved["comments"] is None and saved["participant"] == "P-free" and saved["design"] == "free-rule"
    assert saved["final_video_watched"] == "ended" and saved["final_video_server_seconds"] >= 0
    again = http.post(q, json={"final_attempt": "yes", "rule": "changed my mind"})
    assert again.status_code == 409 and again.json()["error"]["code"] == "already_submitted"
    assert json.loads((folder / "questionnaire.json").read_text()) == saved
    assert httpx.get(f"{api}/sessions/{sid}").json()["questionnaire"]["submitted"]


@pytest.mark.slow
def test_assigned_rule_is_shown_scored_and_exported_with_hidden_guesses(live_server, tmp_path, http):
    srv = live_server("bayes-preference", rounds=1, seed=3, video_size=(64, 64), intention="color-match")
    api = f"{srv.url}/api"
    config = httpx.get(f"{api}/config").json()
    assert config["design"] == "assigned-rule" and "intention" not in config  # the rule's name: never
    assert config["intention_description"] == "Put each block in the bowl of the same colour."
    assert config["show_estimate"] == "hidden" and config["video_size"] == [64, 64]
    sid = http.post(f"{api}/sessions", json={"participant": "P-assigned"}).json()["id"]
    state = _waiting(srv.url, sid, 1)
    assert state["design"] == "assigned-rule" and state["estimate"] is None
    http.post(f"{api}/sessions/{sid}/answer", json={"kind": "preference", "round": 1, "choice": "B"})
    session = srv.manager.get(sid)
    assert session.join(300) and session.status == "finished", session.error
    state = httpx.get(f"{api}/sessions/{sid}").json()
    assert state["estimate"] is None  # hidden: not even the final guess
    summary = json.loads((srv.session_dir(sid) / "summary.json").read_text())
    assert summary["success_basis"] == "assigned-rule" and summary["intention"] == "color-match"
    assert summary["success"] is None or 0 <= summary["success"] <= 1
    http.post(f"{api}/sessions/{sid}/final-video", json={"event": "ended"}).raise_for_status()
    res = http.post(f"{api}/sessions/{sid}/questionnaire", json={"final_attempt": "no", "rule": "same colours"})
    assert res.status_code == 201

    table = tmp_path / "study.jsonl"
    res = CliRunner().invoke(app, ["study-export", str(srv.out), "--to", str(table)])
    assert res.exit_code == 0, res.output
    (row,) = [json.loads(x) for x in table.read_text().splitlines()]
    assert row["participant"] == "P-assigned" and row["design"] == "assigned-rule"
    assert row["intention"] == "color-match" and row["success"] == summary["success"]
    assert [r["answer"] for r in row["rounds"]] == ["B"] and row["rounds"][0]["response_s"] >= 0
    assert row["questionnaire_final_attempt"] == "no" and row["questionnaire_rule"] == "same colours"
    assert row["status"] == "finished" and row["show_estimate"] == "hidden"


def test_the_corpus_export_keeps_free_rule_words_and_leaves_assigned_rules_out(tmp_path):
    """study-export --corpus: a lab fits its population's prior on a pilot's own words; an
    assigned-rule participant paraphrases the rule given, so those never enter it."""
    from activeintent.goals.prior import PriorError, read_corpus

    out = tmp_path / "study"
    _fake_session(out, "a" * 16, 1000.0, "assigned-rule", "color-match",
                  {"final_attempt": "yes", "rule": "blocks in the bowl of their colour"})
    _fake_session(out, "b" * 16, 2000.0, "free-rule", None, {"final_attempt": "yes", "rule": "  tall towers please "})
    _fake_session(out, "c" * 16, 3000.0, "free-rule", None, {"final_attempt": "no", "rule": ""})
    corpus = tmp_path / "corpus.jsonl"
    res = CliRunner().invoke(app, ["study-export", str(out), "--to", str(tmp_path / "s.csv"), "--corpus", str(corpus)])
    assert res.exit_code == 0, res.output
    rows = [json.loads(x) for x in corpus.read_text().splitlines()]
    assert [r["request"] for r in rows] == ["tall towers please"]  # the free-rule answer, as typed
    assert rows[0]["id"] == "b" * 16 and rows[0]["goal"] is None and rows[0]["writer"]
    assert "colour" not in corpus.read_text()  # the assigned rule never leaks in
    with pytest.raises(PriorError, match="no translated request"):  # untranslated: nothing to fit yet
        read_corpus(corpus)
