"""`activeintent study-export`: the sessions of one study as one table.

A study's ``--out`` folder holds one sub-folder per session (see :mod:`activeintent.web.session`).
Each becomes one record: who took part (participant code), under which design and rule, what
they answered in every round and how long each answer took, how the session ended, success
(assigned-rule sessions only; ``None`` otherwise) and the end-of-session questionnaire.

``.jsonl`` keeps every record as it is (the answers per round as a list, the full *h*); ``.csv``
flattens it to one row per session with ``round<i>_*`` columns for every round any session
reached. Free text goes into the CSV as typed, except that a cell starting with ``=``, ``+``,
``-``, ``@``, a tab or a carriage return gets a leading ``'`` so that a spreadsheet shows it
as text instead of running it as a formula; the JSONL keeps the text untouched.
"""

from __future__ import annotations

import csv
import json
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from activeintent.records import dumps
from activeintent.signals import answer_kind_from_dump

SESSION_COLUMNS = [
    "session", "participant", "pid", "study_id", "prolific_session_id", "condition", "consented",
    "button_order", "key_id", "created", "ended", "status", "design", "intention", "intention_description",
    "method", "signal", "show_estimate", "video_size", "seed", "rounds_planned", "rounds_answered",
    "signals_used", "answers", "answer_seconds_total", "session_seconds", "stalls_total", "stall_seconds_total", "success", "success_basis",
    "final_guess", "final_scene", "final_scene_index", "final_scene_feasible", "error", "final_video_watched", "final_video_seconds",
    "final_video_server_seconds",
    "questionnaire_final_attempt", "questionnaire_rule", "questionnaire_comments",
    "questionnaire_submitted",
]
ROUND_COLUMNS = ["participant", "key", "answer", "stop_time", "viewing", "after_end_presses", "response_s",
                 "stalls", "stall_s", "counted", "guess"]
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")


def _iso(ts: Any) -> str | None:
    if not isinstance(ts, int | float):
        return None
    return datetime.fromtimestamp(ts, tz=UTC).isoformat(timespec="seconds")


def _read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def _read_lines(path: Path) -> list[dict]:
    out = []
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return out
    for line in text.splitlines():
        try:
            value = json.loads(line)
        except ValueError:
            continue  # a torn last line of a session that was killed
        if isinstance(value, dict):
            out.append(value)
    return out


def _status(info: dict, folder: Path, events: list[dict]) -> str:
    status = info.get("status")
    if status in ("finished", "failed", "cancelled"):
        return status
    for e in reversed(events):  # folders written before session.json kept the status
        kind = e.get("type") if e.get("source") == "server" else None
        if kind in ("session_finished", "session_failed", "session_cancelled"):
            return kind.removeprefix("session_")
    return "finished" if (folder / "summary.json").exists() else "incomplete"


def study_fields(study: dict) -> dict:
    """A session.json's study as the fields exports read (a versioned reader: sessions written
    before the study held a run spec kept method, rounds and intention flat)."""
    run = study.get("run")
    if not isinstance(run, dict):
        return study
    learner, protocol = run.get("learner") or {}, run.get("protocol") or {}
    return {**study, "method": learner.get("method"), "rounds": protocol.get("budget"),
            "intention": study.get("intention_name")}


def session_record(folder: Path) -> dict:
    """One session folder as one record (ValueError when it is not a session's folder)."""
    info = _read_json(folder / "session.json")
    if not isinstance(info, dict) or not isinstance(info.get("study"), dict):
        raise ValueError("no readable session.json")
    study = study_fields(info["study"])
    design = info.get("design") or study.get("design") or "unknown"
    summary = _read_json(folder / "summary.json")
    summary = summary if isinstance(summary, dict) else {}
    questionnaire = _read_json(folder / "questionnaire.json")
    questionnaire = questionnaire if isinstance(questionnaire, dict) else {}
    events = _read_lines(folder / "events.jsonl")
    server = [e for e in events if e.get("source") == "server"]
    presented = {e.get("round"): e.get("server_ts") for e in server if e.get("type") == "round_presented"}
    answered_at = {e.get("round"): e.get("server_ts") for e in server if e.get("type") == "answer"}
    viewing = {e.get("round"): (e.get("client") or {}).get("viewing") for e in server if e.get("type") == "answer"}
    answered_by = {e.get("round"): e.get("answered_by") for e in server if e.get("type") == "answer"}
    # presses of Stop once the video had ended: refused by the page, or by the server
    late: dict = {}
    for e in events:
        if e.get("type") == "stop_after_end":
            late[e.get("round")] = late.get(e.get("round"), 0) + 1
    # the videos' stalls as the page measured them (playback waiting for frames), per round
    stalls: dict = {}
    for e in events:
        if e.get("type") == "video_stall" and e.get("source") == "client":
            seconds = (e.get("data") or {}).get("seconds")
            count, total = stalls.get(e.get("round"), (0, 0.0))
            stalls[e.get("round")] = (count + 1, total + (seconds if isinstance(seconds, int | float) else 0.0))
    participant = info.get("participant")

    rounds = []
    for r in _read_lines(folder / "rounds.jsonl"):
        n = r.get("round")
        h = r.get("answer") if isinstance(r.get("answer"), dict) else {}
        t0, t1 = presented.get(n), answered_at.get(n)
        response = round(t1 - t0, 3) if isinstance(t0, int | float) and isinstance(t1, int | float) else None
        label = answer_kind_from_dump(h)
        # who gave the answer, as the server saw it (sessions before the key cookie: unknown)
        by = r.get("answered_by") or answered_by.get(n)
        by = by if isinstance(by, dict) else {}
        rounds.append({
            "round": n,
            "participant": by.get("participant", participant),  # on every row: a round table stands on its own
            "key": by.get("key"),
            "answer": label,
            "stop_time": h.get("stop_time"),
            # a stop in the first viewing or in a replay after it (older sessions: first)
            "viewing": (viewing.get(n) or "first") if label == "stop" else None,
            "after_end_presses": late.get(n, 0),
            "response_s": response,
            "stalls": stalls.get(n, (0, 0.0))[0],
            "stall_s": round(stalls.get(n, (0, 0.0))[1], 3),
            "counted": r.get("counted"),
            "guess": r.get("z"),  # the learner's z when this round was asked (not necessarily shown)
            "h": h,
        })
    responses = [r["response_s"] for r in rounds if r["response_s"] is not None]
    created, ended = info.get("created"), info.get("ended")
    scored = design == "assigned-rule"  # nothing else is scored: see session.study_summary
    size = study.get("video_size")
    return {
        "session": info.get("id") or folder.name,
        "participant": participant,
        "pid": info.get("pid"),
        "study_id": info.get("study_id"),
        "prolific_session_id": info.get("prolific_session_id"),
        "condition": info.get("condition", "single"),
        "consented": _iso(info.get("consented")),
        "button_order": " ".join(info.get("button_order") or []) or None,
        "key_id": info.get("key_id"),
        "created": _iso(created),
        "ended": _iso(ended),
        "status": _status(info, folder, server),
        "design": design,
        "intention": study.get("intention") if scored else None,
        "intention_description": study.get("intention_description") if scored else None,
        "method": study.get("method"),
        "signal": study.get("signal"),
        "show_estimate": info.get("show_estimate", study.get("show_estimate")),
        "video_size": "x".join(str(v) for v in size) if isinstance(size, list) else None,
        "seed": info.get("seed"),
        "rounds_planned": study.get("rounds"),
        "rounds_answered": len(rounds),
        "signals_used": summary.get("signals_used", sum(bool(r["counted"]) for r in rounds)),
        "answers": " ".join(r["answer"] for r in rounds),
        "answer_seconds_total": round(sum(responses), 3) if responses else None,
        "session_seconds": round(ended - created, 3) if isinstance(created, int | float)
        and isinstance(ended, int | float) else None,
        "stalls_total": sum(c for c, _ in stalls.values()),  # the final video's too
        "stall_seconds_total": round(sum(t for _, t in stalls.values()), 3),
        "success": summary.get("success") if scored else None,
        "success_basis": (summary.get("success_basis") or "assigned-rule") if scored and summary else "none",
        "final_guess": summary.get("final_z") or None,
        "final_scene": ", ".join(info["final_scene"]) if isinstance(info.get("final_scene"), list) else None,
        "final_scene_index": info.get("final_scene_index"),
        "final_scene_feasible": info.get("final_scene_feasible"),
        "error": info.get("error") or summary.get("error"),
        # whether the final attempt's video was watched before the questions opened, and how long
        "final_video_watched": questionnaire.get("final_video_watched"),
        "final_video_seconds": questionnaire.get("final_video_seconds"),
        "final_video_server_seconds": questionnaire.get("final_video_server_seconds"),
        "questionnaire_final_attempt": questionnaire.get("final_attempt"),
        "questionnaire_rule": questionnaire.get("rule"),
        "questionnaire_comments": questionnaire.get("comments"),
        "questionnaire_submitted": _iso(questionnaire.get("submitted")),
        "rounds": rounds,
    }


def corpus_rows(records: list[dict]) -> list[dict]:
    """The "your rule in your words" answers of free-rule sessions, in the corpus format of
    data/requests (``request``, ``writer`` = the participant code, ``date``; ``goal`` null until
    someone translates it into the goal language, as `prior fit` reads). Assigned-rule sessions
    are left out: their participants paraphrase the rule they were given."""
    out = []
    for r in records:
        words = (r.get("questionnaire_rule") or "").strip()
        if r.get("design") != "free-rule" or not words:
            continue
        date = (r.get("questionnaire_submitted") or r.get("ended") or "")[:10] or None
        out.append({"id": r["session"], "request": words, "writer": r.get("participant") or r["session"],
                    "date": date, "goal": None})
    return out


def collect_sessions(out_dir: Path) -> tuple[list[dict], list[tuple[Path, str]]]:
    """The records of every session folder in ``out_dir`` (oldest first) and the folders
    skipped, with why."""
    records, skipped = [], []
    for folder in sorted(p for p in out_dir.iterdir() if p.is_dir()):
        if not (folder / "session.json").exists():
            continue  # not a session's folder
        try:
            records.append(session_record(folder))
        except ValueError as err:
            skipped.append((folder, str(err)))
    records.sort(key=lambda r: (r["created"] or "", r["session"]))
    return records, skipped


def _cell(value: Any) -> Any:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str) and value.startswith(FORMULA_START):
        return "'" + value
    return value


def csv_rows(records: list[dict]) -> tuple[list[str], list[dict]]:
    """Column names and flat rows: the session's fields, then ``round<i>_*`` per round."""
    most = max((len(r["rounds"]) for r in records), default=0)
    columns = SESSION_COLUMNS + [f"round{i}_{c}" for i in range(1, most + 1) for c in ROUND_COLUMNS]
    rows = []
    for r in records:
        row = {c: _cell(r[c]) for c in SESSION_COLUMNS}
        for i, rnd in enumerate(r["rounds"], 1):
            row.update({f"round{i}_{c}": _cell(rnd[c]) for c in ROUND_COLUMNS})
        rows.append(row)
    return columns, rows


def write_table(records: list[dict], to: Path) -> None:
    """``to`` as CSV or JSONL, by its suffix."""
    to.parent.mkdir(parents=True, exist_ok=True)
    if to.suffix.lower() == ".jsonl":
        to.write_text("".join(dumps(r) + "\n" for r in records), encoding="utf-8")
        return
    columns, rows = csv_rows(records)
    with to.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=columns, restval="")
        writer.writeheader()
        writer.writerows(rows)
