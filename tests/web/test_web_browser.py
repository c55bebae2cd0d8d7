"""Participants' sessions in a real browser (Debian's Chromium driven by Playwright) against a
live study server; the saved logs must hold the signals the clicks meant.

Screenshots of every page are taken into the test's folder; with
ACTIVEINTENT_UPDATE_SCREENSHOTS=1 they are also copied to docs/img/webapp-*.png.
"""

from __future__ import annotations

import csv
import json
import math
import os
import shutil
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import pytest
from typer.testing import CliRunner

from activeintent.cli import app
from activeintent.records import read_rounds
from activeintent.sim.env import SimConfig
from activeintent.web.session_view import session_state

DOCS_IMG = Path(__file__).resolve().parents[2] / "docs" / "img"
UPDATING = os.environ.get("ACTIVEINTENT_UPDATE_SCREENSHOTS") == "1"
# small videos keep the tests quick; the documentation's screenshots show the study's default
VIDEO = {} if UPDATING else {"video_size": (240, 240)}

pytestmark = pytest.mark.slow  # a browser and whole episodes


def shot(page, tmp_path: Path, name: str) -> Path:
    path = tmp_path / f"webapp-{name}.png"
    page.screenshot(path=str(path), full_page=True)
    assert path.stat().st_size > 10_000 and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    if UPDATING:
        DOCS_IMG.mkdir(parents=True, exist_ok=True)
        shutil.copy(path, DOCS_IMG / path.name)
    return path


def session_id(page) -> str:
    return parse_qs(urlsplit(page.url).query)["session"][0]


def events(folder: Path) -> list[dict]:
    return [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]


def wait_round(page, n: int) -> None:
    page.wait_for_selector(f'#question[data-round="{n}"]:not(.hidden)')


def wait_videos(page, *ids: str) -> None:
    page.wait_for_function(
        "ids => ids.every(id => document.getElementById(id).readyState >= 2)", arg=list(ids)
    )


def enter(page, url: str, participant: str | None = None) -> None:
    """Step 1 of the start page (consent, code); ends on step 2, what to do."""
    page.goto(url)
    page.wait_for_selector("#begin:enabled")
    if participant is not None:
        page.fill("#participant", participant)
    page.click("#begin")
    page.wait_for_selector("#start:enabled")


def start(page, url: str, participant: str, tmp_path: Path | None = None) -> str:
    enter(page, url + "/", participant)
    if tmp_path is not None:
        shot(page, tmp_path, "start")
    page.click("#start")
    page.wait_for_function("location.pathname !== '/'")
    return session_id(page)


def ready(page) -> None:
    """Pass the round's ready gate (the videos play only then)."""
    page.wait_for_selector("#ready:enabled")
    page.click("#ready")
    page.wait_for_selector("#gate", state="hidden")


def near_end(page, length: float, before: float) -> None:
    """Jump the video to ``before`` seconds before its end. ``length`` is the server's: a browser
    learns the length of a video that is still being drawn only once it has all of it."""
    page.evaluate("([t, b]) => { const v = document.getElementById('video'); v.currentTime = Math.max(0, t - b); "
                  "v.play(); }", [length, before])


def test_two_round_preference_session(live_server, page, tmp_path):
    srv = live_server("bayes-preference", rounds=2, seed=3, **VIDEO)
    sid = start(page, srv.url, "P-pref", tmp_path)
    assert urlsplit(page.url).path == "/signal/preference"

    wait_round(page, 1)
    wait_videos(page, "video-a", "video-b")
    assert page.is_disabled('button[data-choice="A"]')  # nothing to answer before the videos played
    assert page.evaluate("document.getElementById('video-a').paused")  # no autoplay: the gate first
    ready(page)
    assert page.inner_text("#progress .label") == "Round 1 of 2"
    assert not page.is_visible("#estimate")  # the guess is hidden (the study's default)
    for v in ("video-a", "video-b"):  # autoplaying, looping videos
        assert page.evaluate(f"document.getElementById('{v}').loop")
    page.wait_for_function("document.getElementById('video-a').currentTime > 0")
    shot(page, tmp_path, "preference")
    page.click('button[data-choice="A"]')

    wait_round(page, 2)
    assert page.inner_text("#progress .label") == "Round 2 of 2"
    page.wait_for_selector("#ready:enabled")  # once both videos are loaded whole
    page.keyboard.press("Enter")  # the gate's key
    page.wait_for_selector('button[data-choice="cant_choose"]:enabled')
    page.click('button[data-choice="cant_choose"]')

    page.wait_for_url("**/done?session=*")
    page.wait_for_selector("#question:not(.hidden)")
    wait_videos(page, "final")
    page.wait_for_selector("#questionnaire:visible")
    shot(page, tmp_path, "thank-you")
    assert page.is_visible("#q-final") and page.is_visible("#q-rule")

    session = srv.manager.get(sid)
    assert session.join(120) and session.status == "finished", session.error
    folder = srv.session_dir(sid)
    rounds = read_rounds(folder / "rounds.jsonl")
    assert [r["answer"] for r in rounds] == [
        {"signal": "preference", "new_scene": False, "choice": "A"},
        {"signal": "preference", "new_scene": False, "choice": "cant_choose"},
    ]
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["method"] == "bayes-preference" and summary["signals_used"] == 2
    for name in ("round1_a", "round1_b", "round2_a", "round2_b"):
        assert (folder / f"{name}.webm").stat().st_size > 0
    assert (folder / "final.webm").exists()
    log = events(folder)
    choices = [(e["round"], e["data"]["choice"]) for e in log if e["type"] == "choice"]
    assert choices == [(1, "A"), (2, "cant_choose")]
    assert all(e["server_ts"] > 0 and (e["source"] == "server" or e["client_ts"] > 0) for e in log)
    assert {"page_load", "round_shown", "video_playing", "answer_accepted"} <= {e["type"] for e in log}
    assert json.loads((folder / "session.json").read_text())["participant"] == "P-pref"


def test_clicker_session_stops_at_a_known_moment(live_server, page, tmp_path):
    srv = live_server("bayes-stop", rounds=2, seed=4, **VIDEO)
    sid = start(page, srv.url, "P-stop")
    assert urlsplit(page.url).path == "/signal/stop"
    folder = srv.session_dir(sid)

    wait_round(page, 1)
    wait_videos(page, "video")
    ready(page)
    assert not page.evaluate("document.getElementById('video').loop")  # plays once
    video = session_state(srv.manager.get(sid))["question"]["videos"][0]
    fps = video["fps"]
    # the moment to stop: the middle of a frame about 40% into the video
    k = int(0.4 * (video["frames"] - 1))
    target = (k + 0.5) / fps
    page.wait_for_function("document.getElementById('video').currentTime > 0")
    at = page.evaluate(
        """async (t) => {
            const v = document.getElementById('video');
            v.pause();
            const seeked = new Promise(r => v.addEventListener('seeked', r, {once: true}));
            v.currentTime = t;
            await seeked;
            return v.currentTime;
        }""",
        target,
    )
    assert at == pytest.approx(target, abs=1e-3)
    shot(page, tmp_path, "clicker")
    page.keyboard.press("Space")  # the Stop shortcut

    wait_round(page, 2)
    wait_videos(page, "video")
    ready(page)
    assert page.is_disabled("#good")  # not before the video has ended
    near_end(page, session_state(srv.manager.get(sid))["question"]["videos"][0]["duration"], 0.3)
    page.wait_for_selector("#good:enabled")
    page.click("#good")

    page.wait_for_url("**/done?session=*")
    session = srv.manager.get(sid)
    assert session.join(120) and session.status == "finished", session.error
    rounds = read_rounds(folder / "rounds.jsonl")
    assert len(rounds) == 2
    h1, h2 = rounds[0]["answer"], rounds[1]["answer"]
    log_hz = SimConfig().log_hz
    assert h1["signal"] == "stop" and not h1["new_scene"]
    assert h1["stop_time"] == pytest.approx(target, abs=1e-3)
    assert h1["frame"] == k == math.floor(h1["stop_time"] * fps)
    # within one video frame of the intended tick
    assert abs(h1["tick"] - round(target * log_hz)) <= log_hz / fps
    assert h2 == {"signal": "stop", "stop_time": None, "tick": None, "frame": None, "new_scene": False}
    log = events(folder)
    stops = [e for e in log if e["type"] == "stop"]
    assert len(stops) == 1 and stops[0]["data"]["via"] == "key" and stops[0]["round"] == 1
    assert [e["data"]["via"] for e in log if e["type"] == "no_stop"] == ["click"]
    answers = [e for e in log if e["type"] == "answer" and e["source"] == "server"]
    assert [a["answer"] for a in answers] == [h1, h2]


def export(out: Path, to: Path) -> list[dict]:
    res = CliRunner().invoke(app, ["study-export", str(out), "--to", str(to)])
    assert res.exit_code == 0, res.output
    if to.suffix == ".jsonl":
        return [json.loads(line) for line in to.read_text().splitlines()]
    return list(csv.DictReader(to.open(newline="")))


def watch_final(page) -> None:
    """Play the final attempt to its end (the questions open only then), quickly: from near it."""
    if page.get_attribute("#questionnaire", "data-locked") != "true":
        return
    page.wait_for_function("Number.isFinite(document.getElementById('final').duration)")
    page.evaluate("() => { const v = document.getElementById('final'); v.currentTime = Math.max(0, v.duration - 0.3); "
                  "v.play(); }")
    page.wait_for_selector("#q-submit:enabled")


def answer_questionnaire(page, final_attempt: str, rule: str, comments: str) -> None:
    page.wait_for_selector("#questionnaire:visible")
    watch_final(page)
    page.click("#q-submit")  # nothing chosen yet: the page asks first and sends nothing
    assert "Please answer" in page.inner_text("#q-status")
    page.get_by_role("radio", name=final_attempt.capitalize(), exact=True).check()
    page.fill("#q-rule", rule)
    page.fill("#q-comments", comments)
    page.get_by_role("button", name="Send my answers").click()
    page.wait_for_selector("#finished:visible")
    assert not page.is_visible("#questionnaire")


def test_free_and_assigned_rule_sessions_end_with_the_questionnaire(live_server, page, tmp_path):
    small = {"video_size": (160, 160)}

    # -- free rule: each participant picks a rule; the guess stays hidden; nothing is scored ----
    free = live_server("bayes-preference", rounds=1, seed=5, **small)
    enter(page, free.url + "/", "P-free")
    assert page.is_visible("#rule-free") and not page.is_visible("#rule-assigned")
    page.click("#start")
    page.wait_for_url("**/signal/preference?session=*")
    sid = session_id(page)
    wait_round(page, 1)
    ready(page)
    # controls are named by what they do; the key hints are outside the names
    for name in ("A is better", "B is better", "Can't choose", "New scene"):
        assert page.get_by_role("button", name=name, exact=True).count() == 1, name
    assert page.evaluate("[...document.querySelectorAll('button kbd')].every(k => k.getAttribute('aria-hidden') === 'true')")
    assert page.get_attribute("#video-a", "aria-label").startswith("Video A")
    scene = session_state(free.manager.get(sid))["question"]["scene"]
    assert all(name in page.text_content("#caption-a") for name in scene)
    assert not page.is_visible("#estimate")
    assert not page.is_visible("#legend")
    page.get_by_role("button", name="Show colour names").click()
    assert page.is_visible("#legend") and page.get_attribute("#legend-toggle", "aria-expanded") == "true"
    assert page.locator("#legend-list li").all_inner_texts() == scene
    page.keyboard.press("b")

    page.wait_for_url("**/done?session=*")
    page.wait_for_selector("#question:not(.hidden)")
    assert page.is_visible("#q-final")
    ready(page)  # the final attempt has its gate too
    assert page.is_visible("#legend")  # colour names stay on once asked for
    answer_questionnaire(page, "partly", "Warm colours to the left", "The videos were clear.")
    assert not page.is_visible("#estimate")  # hidden study: not even the final guess
    summary = json.loads((free.session_dir(sid) / "summary.json").read_text())
    assert summary["success"] is None and summary["success_basis"] == "none" and summary["intention"] is None
    (row,) = export(free.out, tmp_path / "free.csv")
    assert row["session"] == sid and row["participant"] == "P-free" and row["design"] == "free-rule"
    assert row["success"] == "" and row["success_basis"] == "none" and row["intention"] == ""
    assert row["round1_answer"] == "B" and row["status"] == "finished"
    assert row["questionnaire_final_attempt"] == "partly"
    assert row["questionnaire_rule"] == "Warm colours to the left"
    assert row["questionnaire_comments"] == "The videos were clear."

    # -- assigned rule: told on the start page, guesses shown after each answer, stop kept ------
    assigned = live_server("bayes-stop", rounds=2, seed=6, intention="color-match", show_estimate="after-answer",
                           **small)
    enter(page, assigned.url + "/", "P-assigned")
    assert page.is_visible("#rule-assigned") and not page.is_visible("#rule-free")
    assert page.inner_text("#rule-text") == "Put each block in the bowl of the same colour."
    page.click("#start")
    page.wait_for_url("**/signal/stop?session=*")
    sid = session_id(page)
    wait_round(page, 1)
    ready(page)
    assert not page.is_visible("#feedback") and not page.is_visible("#estimate")  # no guess in round 1
    assert page.get_by_role("button", name="Stop the robot", exact=True).count() == 1
    wait_videos(page, "video")
    page.wait_for_function("document.getElementById('video').currentTime > 0.3")
    # record what the page shows at the moment the stop is confirmed (before any later poll)
    page.evaluate(
        """() => {
            const badge = document.getElementById('stop-badge');
            new MutationObserver((_, obs) => {
                if (badge.classList.contains('hidden')) return;
                const v = document.getElementById('video');
                window.atStop = {question: !document.getElementById('question').classList.contains('hidden'),
                                 paused: v.paused, time: v.currentTime, src: v.dataset.url,
                                 blob: v.currentSrc.startsWith('blob:'),
                                 marker: !document.querySelector('#timeline .marker').classList.contains('hidden')};
                obs.disconnect();
            }).observe(badge, {attributes: true});
        }"""
    )
    page.keyboard.press("Space")
    page.wait_for_function("window.atStop !== undefined")
    at_stop = page.evaluate("window.atStop")
    assert at_stop["question"] and at_stop["paused"] and at_stop["marker"] and "round1_y" in at_stop["src"]
    assert at_stop["blob"]  # it played from memory: fetched whole before Ready enabled
    assert at_stop["src"].endswith(".mp4")  # H.264 where the browser plays it (Chromium does)

    page.wait_for_selector("#feedback:visible")  # round 2 is ready: first the guess, then the video
    assert not page.is_visible("#question")
    assert page.inner_text("#feedback .guess")
    assert "% sure" in page.inner_text("#feedback .confidence")
    page.get_by_role("button", name="Continue to round 2 of 2").click()
    wait_round(page, 2)
    assert not page.is_visible("#feedback") and not page.is_visible("#stop-badge")
    page.keyboard.press("n")

    page.wait_for_url("**/done?session=*")
    page.wait_for_selector("#question:not(.hidden)")
    assert page.inner_text("#q-rule-label").startswith("In your own words")
    assert not page.is_visible("#estimate")  # not before the questionnaire is answered
    answer_questionnaire(page, "yes", "Blocks into the bowl of their colour", "")
    assert page.is_visible("#estimate") and page.inner_text("#estimate .guess")
    session = assigned.manager.get(sid)
    assert session.join(60) and session.status == "finished", session.error
    (row,) = export(assigned.out, tmp_path / "assigned.jsonl")
    summary = json.loads((assigned.session_dir(sid) / "summary.json").read_text())
    assert row["design"] == "assigned-rule" and row["intention"] == "color-match"
    assert summary["success_basis"] == "assigned-rule" and row["success"] == summary["success"]
    assert [r["answer"] for r in row["rounds"]] == ["stop", "new_scene"]
    assert row["rounds"][0]["stop_time"] == pytest.approx(at_stop["time"], abs=1e-3)
    assert row["questionnaire_final_attempt"] == "yes"
    assert row["questionnaire_rule"] == "Blocks into the bowl of their colour"
    assert row["questionnaire_comments"] is None and row["show_estimate"] == "after-answer"
    loaded = [e for e in events(assigned.session_dir(sid)) if e["type"] == "videos_loaded"]
    assert {1, None} <= {e["round"] for e in loaded}  # round 1's video and the final one, whole
    assert all(b > 0 for e in loaded for b in e["data"]["bytes"])


def test_a_whole_assigned_rule_study_from_a_link(live_server, page, tmp_path):
    """A participant from a Prolific-style link: consent, ready gates, a Stop pressed after the
    video has ended (refused, on record), a stop in a replay, the questionnaire and the
    completion code; the data hold the pid, the condition and a final table that can show the rule."""
    import httpx

    from activeintent.suites import resolve
    from activeintent.web.study import StudyFile
    from activeintent.world.scene import Scene

    study = StudyFile(
        consent="We ask you to teach a robot a rule.\n\nYou may stop at any time.", completion_code="DONE-7",
        redirect_url="https://example.org/complete?cc=DONE-7", redirect_after_s=None, assignment_seed=2,
        conditions=[{"name": "stop-after", "method": "bayes-stop", "intention": "color-match",
                     "show_estimate": "after-answer"},
                    {"name": "stop-always", "method": "bayes-stop", "intention": "color-match",
                     "show_estimate": "always"}])
    # seed 3: the first two test tables cannot show color-match, the third can
    srv = live_server("bayes-stop", rounds=2, seed=3, study_file=study, video_size=(160, 160))
    expected = srv.manager.assigner.tie_order[0]  # the first participant: all at 0, the seeded order decides
    page.goto(f"{srv.url}/?pid=P-study-01&STUDY_ID=study42&SESSION_ID=visit9")
    page.wait_for_selector("#begin:enabled")
    assert page.is_visible("#consent") and "You may stop at any time." in page.inner_text("#consent-text")
    assert page.inner_text("#pid-value") == "P-study-01" and not page.is_visible("#participant")
    page.click("#begin")
    page.wait_for_selector("#start:enabled")
    text = page.inner_text("body").lower()
    assert "bayes" not in text and "signal" not in text and expected not in text  # no method, no condition
    page.click("#start")
    page.wait_for_url("**/signal/stop?session=*")
    sid = session_id(page)
    api = f"{srv.url}/api/sessions/{sid}"
    session = srv.manager.get(sid)
    assert session.enrolment.condition == expected
    assert session.config.show_estimate == study.condition(expected).show_estimate
    # the browser holds the session's key: for this session's API only, out of the page's reach
    (key,) = [c for c in page.context.cookies() if c["name"] == "activeintent_key"]
    assert key["path"] == f"/api/sessions/{sid}" and key["httpOnly"] and key["sameSite"] == "Strict"
    assert "activeintent_key" not in page.evaluate("document.cookie")

    # -- round 1: ready gate, the video ends, a late Stop, a stop in the replay --------------------
    wait_round(page, 1)
    wait_videos(page, "video")
    assert page.is_visible("#gate") and page.is_disabled("#stop")
    assert page.evaluate("document.getElementById('video').paused")  # nothing plays before Ready
    order = [page.get_attribute(f"#answers button:nth-child({i})", "data-action") for i in (1, 2)]
    assert order == session.enrolment.button_order
    assert page.evaluate("new Set([...document.querySelectorAll('#answers button')].map(b => b.className)).size") == 1
    page.wait_for_selector("#ready:enabled")
    page.keyboard.press("Enter")  # Ready
    page.wait_for_selector('#question[data-phase="first"]')
    video = session_state(session)["question"]["videos"][0]
    near_end(page, video["duration"], 0.05)
    page.wait_for_selector('#question[data-phase="ended"]')
    assert page.is_disabled("#stop") and page.is_enabled("#good")
    page.keyboard.press("Space")  # too late: the video has ended
    page.wait_for_function("document.getElementById('status').textContent.includes('no longer counts')")
    assert page.is_visible("#replay")
    # the server refuses it too: once the page said the video ended, and at the video's end
    for _ in range(600):  # the page reports the end as it happens; wait for that report
        if session.viewing(1)["ended"] is not None:
            break
        page.wait_for_timeout(50)
    assert session.viewing(1)["ended"] is not None, "the page did not report the video's end"
    # (sent with the browser's cookies, as the page would send them; without them: refused)
    stop = {"kind": "stop", "round": 1, "action": "stop", "time": 1.0}
    assert httpx.post(f"{api}/answer", json=stop).json()["error"]["code"] == "not_session_owner"
    late = page.request.post(f"{api}/answer", data=stop)
    assert late.status == 422 and late.json()["error"]["code"] == "after_video_end"
    at_end = page.request.post(f"{api}/answer", data={"kind": "stop", "round": 1, "action": "stop",
                                                      "time": video["duration"], "viewing": "replay"})
    assert at_end.status == 422 and "at or after the end" in at_end.json()["error"]["message"]
    page.click("#replay")
    page.wait_for_selector('#question[data-phase="replay"]')
    target = (int(0.4 * (video["frames"] - 1)) + 0.5) / video["fps"]
    page.evaluate("""async (t) => {
        const v = document.getElementById('video');
        v.pause();
        const seeked = new Promise(r => v.addEventListener('seeked', r, {once: true}));
        v.currentTime = t;
        await seeked;
    }""", target)
    page.keyboard.press("Space")  # a stop during the replay

    # -- round 2: guess between rounds (after-answer) or above the video (always) ------------------
    if session.config.show_estimate == "after-answer":
        page.wait_for_selector("#feedback:visible")
        page.get_by_role("button", name="Continue to round 2 of 2").click()
    wait_round(page, 2)
    wait_videos(page, "video")
    ready(page)
    near_end(page, session_state(session)["question"]["videos"][0]["duration"], 0.05)
    page.wait_for_selector("#good:enabled")
    page.click("#good")

    # -- the final attempt, the questionnaire, the completion code -------------------------------
    page.wait_for_url("**/done?session=*")
    page.wait_for_selector("#question:not(.hidden)")
    assert page.is_visible("#gate")
    ready(page)
    answer_questionnaire(page, "partly", "Each block into the bowl of its colour", "")
    page.wait_for_selector("#completion:visible")
    assert page.inner_text("#completion-code") == "DONE-7"
    assert page.get_attribute("#redirect-link", "href") == "https://example.org/complete?cc=DONE-7"
    confidence = page.inner_text("#estimate .confidence")
    assert "%" in confidence and "does not say" not in confidence  # the Bayesian learner's own confidence

    assert session.join(60) and session.status == "finished", session.error
    folder = srv.session_dir(sid)
    info = json.loads((folder / "session.json").read_text())
    assert info["pid"] == info["participant"] == "P-study-01" and info["condition"] == expected
    assert info["study_id"] == "study42" and info["prolific_session_id"] == "visit9" and info["consented"]
    rule = resolve("color-match", None)
    assert info["final_scene_feasible"] is True and rule.feasible(Scene(objects=info["final_scene"]))
    assert info["final_scene_index"] == 2  # the first test table where color-match can be shown
    log = events(folder)
    assert [e["round"] for e in log if e["type"] == "stop_after_end" and e["source"] == "client"] == [1]
    assert sum(e["type"] == "stop_after_end" and e["source"] == "server" for e in log) == 2  # the refusals
    rows = export(srv.out, tmp_path / "study.csv")
    (row,) = rows
    assert row["pid"] == row["participant"] == row["round1_participant"] == row["round2_participant"] == "P-study-01"
    assert row["condition"] == expected and row["study_id"] == "study42"
    assert row["button_order"] == " ".join(session.enrolment.button_order)
    assert row["final_scene_feasible"] == "true" and row["final_scene_index"] == "2"
    assert row["final_video_watched"] == "ended" and float(row["final_video_server_seconds"]) >= 0  # the server's word
    assert row["round1_answer"] == "stop" and row["round1_viewing"] == "replay"
    assert row["round1_after_end_presses"] == "3" and row["round2_answer"] == "no_stop"
    assert float(row["round1_stop_time"]) == pytest.approx(target, abs=1e-3)
    # one participant: the link's pid, proved by the key cookie of the browser that consented
    assert row["key_id"] == info["key_id"] == row["round1_key"] == row["round2_key"]
    by = {"participant": "P-study-01", "key": info["key_id"], "address": "127.0.0.1"}
    assert [r["answered_by"] for r in read_rounds(folder / "rounds.jsonl")] == [by, by]
    assert json.loads((folder / "questionnaire.json").read_text())["answered_by"] == by
    # no stop time at or after the video's end
    for r in read_rounds(folder / "rounds.jsonl"):
        assert r["answer"]["stop_time"] is None or r["answer"]["stop_time"] < video["duration"] - 1e-9


def test_a_plugin_signal_brings_its_own_page(live_server, page, tmp_path):
    """examples/my_signal.py registers the rating signal with its page (examples/my_signal.html)
    and nothing in the package changes: a participant rates in the browser, and the episode's
    rounds hold the ratings the clicks meant."""
    from activeintent.registry import load_plugin

    load_plugin(Path(__file__).resolve().parents[2] / "examples" / "my_signal.py")
    srv = live_server("bayes-rating", rounds=2, seed=5, **VIDEO)
    sid = start(page, srv.url, "P-rating")
    assert urlsplit(page.url).path == "/signal/rating"
    wait_round(page, 1)
    ready(page)
    page.click('button[data-stars="4"]:enabled')
    wait_round(page, 2)
    ready(page)
    page.click('button[data-new-scene="1"]:enabled')
    page.wait_for_url("**/done?session=*")
    session = srv.manager.get(sid)
    assert session.join(120) and session.status == "finished", session.error
    rounds = read_rounds(srv.session_dir(sid) / "rounds.jsonl")
    assert [r["answer"] for r in rounds] == [{"signal": "rating", "new_scene": False, "stars": 4},
                                             {"signal": "rating", "new_scene": True, "stars": None}]
