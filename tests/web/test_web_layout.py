"""The study on the screens participants have (real Chromium): at 1280×720, 1366×768, 1440×900
and 1920×1080 the preference page shows both videos side by side and every answer button without
scrolling, and the stop page the video, Stop and the other answers; the final questions open only
once the final attempt has played to its end; the participant-code field; and no JSON the pages
read names the method, the condition or the rule (nor the learner's guess in a hidden study).

With ACTIVEINTENT_UPDATE_SCREENSHOTS=1 the screenshots are copied to docs/img/webapp-layout-*.png.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from test_web_browser import enter, export, ready, session_id, wait_round, wait_videos

from activeintent.web.study import StudyFile

pytestmark = pytest.mark.slow  # a browser and whole episodes

SIZES = [(1280, 720), (1366, 768), (1440, 900), (1920, 1080)]
DOCS_IMG = Path(__file__).resolve().parents[2] / "docs" / "img"
UPDATING = os.environ.get("ACTIVEINTENT_UPDATE_SCREENSHOTS") == "1"
VIDEO = {"video_size": (800, 600)}  # the default size: what a study shows


def box(page, selector: str) -> dict:
    b = page.locator(selector).bounding_box()
    assert b is not None, f"{selector} is not on the page"
    return b


def on_screen(page, selector: str, width: int, height: int) -> dict:
    """``selector``'s box, asserted to lie wholly inside the viewport with the page unscrolled."""
    assert page.evaluate("window.scrollY") == 0
    b = box(page, selector)
    assert page.locator(selector).is_visible(), selector
    assert b["x"] >= 0 and b["y"] >= 0, (selector, b)
    assert b["x"] + b["width"] <= width + 0.5 and b["y"] + b["height"] <= height + 0.5, (selector, b, width, height)
    return b


def layout_shot(page, tmp_path: Path, name: str) -> None:
    path = tmp_path / f"webapp-layout-{name}.png"
    page.screenshot(path=str(path))  # the viewport: what is on screen without scrolling
    if UPDATING:
        shutil.copy(path, DOCS_IMG / path.name)


def events_of(folder) -> list[dict]:
    return [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]


def test_pages_fit_one_screen_at_common_sizes(live_server, browser, tmp_path):
    pref = live_server("bayes-preference", rounds=1, seed=3, **VIDEO)
    stop = live_server("bayes-stop", rounds=1, seed=4, **VIDEO)
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    page = context.new_page()
    page.set_default_timeout(120_000)
    try:
        # -- preference: A and B side by side, every answer below them, one screen ---------------
        enter(page, pref.url + "/", "P-layout")
        page.click("#start")
        page.wait_for_url("**/signal/preference?session=*")
        wait_round(page, 1)
        wait_videos(page, "video-a", "video-b")
        ready(page)
        page.wait_for_function("getComputedStyle(document.documentElement).getPropertyValue('--video-ratio') !== ''")
        for width, height in SIZES:
            page.set_viewport_size({"width": width, "height": height})
            page.wait_for_timeout(100)
            a = on_screen(page, "#video-a", width, height)
            b = on_screen(page, "#video-b", width, height)
            assert abs(a["y"] - b["y"]) < 1 and a["x"] + a["width"] <= b["x"], (a, b)  # side by side
            assert a["width"] >= 0.3 * width, a  # not shrunk to a thumbnail
            for choice in ("A", "B", "cant_choose", "new_scene"):
                answer = on_screen(page, f'button[data-choice="{choice}"]', width, height)
                assert answer["y"] >= a["y"] + a["height"], choice  # below the videos
                assert page.is_enabled(f'button[data-choice="{choice}"]')
            for control in ("#replay-a", "#replay-b", "#replay-both", "#legend-toggle"):
                on_screen(page, control, width, height)
            layout_shot(page, tmp_path, f"preference-{width}x{height}")

        # -- stop: the video, Stop, Looks good and New scene on one screen ------------------------
        page.set_viewport_size({"width": 1280, "height": 720})
        enter(page, stop.url + "/", "P-layout-stop")
        page.click("#start")
        page.wait_for_url("**/signal/stop?session=*")
        wait_round(page, 1)
        wait_videos(page, "video")
        assert page.is_disabled("#new-scene") and page.is_disabled("#stop")  # nothing before Ready
        ready(page)
        assert page.is_enabled("#new-scene") and page.is_enabled("#stop")
        page.evaluate("document.getElementById('video').pause()")
        for width, height in SIZES:
            page.set_viewport_size({"width": width, "height": height})
            page.wait_for_timeout(100)
            v = on_screen(page, "#video", width, height)
            assert v["width"] >= 0.3 * width, v
            for control in ("#stop", "#good", "#new-scene", "#legend-toggle"):
                c = on_screen(page, control, width, height)
                assert c["y"] >= v["y"] + v["height"], control
            layout_shot(page, tmp_path, f"stop-{width}x{height}")
    finally:
        context.close()


def test_a_whole_study_from_a_pid_link_leaks_no_condition(live_server, page, tmp_path):
    """From a ?pid= link to the completion code: every JSON the pages read is free of the method,
    the condition's name and the rule's id, and of the guess (hidden study); the session starts
    at Start, not at consent; the final questions open only after the final video's end, and the
    export says it was watched and for how long."""
    study = StudyFile(
        consent="We ask you to teach a robot a rule.", completion_code="CODE-57", redirect_after_s=None,
        conditions=[{"name": "cond-secret", "method": "bayes-preference", "intention": "color-match"}])
    srv = live_server("bayes-preference", rounds=1, seed=3, study_file=study, video_size=(160, 160))
    bodies: list[tuple[str, str]] = []

    def keep(response):
        if "application/json" in (response.headers.get("content-type") or ""):
            try:
                bodies.append((response.url, response.text()))
            except Exception:  # a response the page dropped (e.g. on navigation)
                pass

    page.on("response", keep)
    page.goto(f"{srv.url}/?pid=P-leak-01")
    page.wait_for_selector("#begin:enabled")
    page.click("#begin")
    page.wait_for_selector("#start:enabled")
    sid = session_id(page)
    session = srv.manager.get(sid)
    assert session.status == "enrolled" and not session.running  # agreed, not started: no slot, no episode
    assert not (srv.out / "assignment.json").exists() or "P-leak-01" not in (srv.out / "assignment.json").read_text()
    page.click("#start")
    page.wait_for_url("**/signal/preference?session=*")
    assert session.begun
    wait_round(page, 1)
    ready(page)
    page.click('button[data-choice="A"]')
    page.wait_for_url("**/done?session=*")
    page.wait_for_selector("#question:not(.hidden)")
    # the final questions are closed until the final attempt has played to its end
    assert page.is_visible("#q-locked") and page.is_disabled("#q-submit") and page.is_disabled("#q-rule")
    ready(page)
    assert page.is_disabled("#q-submit")
    page.wait_for_function("Number.isFinite(document.getElementById('final').duration)")
    page.wait_for_function("document.getElementById('final').currentTime > 0.5")
    page.evaluate("() => { const v = document.getElementById('final'); v.currentTime = v.duration - 0.4; }")
    page.wait_for_selector("#q-submit:enabled")
    assert not page.is_visible("#q-locked") and page.is_visible("#replay")
    page.get_by_role("radio", name="Yes", exact=True).check()
    page.fill("#q-rule", "Blocks go to their own colour")
    page.get_by_role("button", name="Send my answers").click()
    page.wait_for_selector("#completion:visible")
    assert page.inner_text("#completion-code") == "CODE-57"
    page.wait_for_timeout(500)  # the last polls

    reads = [(url, text) for url, text in bodies if "/api/" in url]
    assert any(url.endswith("/api/config") for url, _ in reads) and any(f"/api/sessions/{sid}" in u for u, _ in reads)
    for url, text in reads:
        lower = text.lower()
        for secret in ("bayes", "cond-secret", "color-match", "color_match", '"method"', '"intention"'):
            assert secret not in lower, (secret, url, text[:300])
        data = json.loads(text)
        if isinstance(data, dict) and "estimate" in data:
            assert data["estimate"] is None, url  # a hidden study: never the learner's guess
    assert session.join(60) and session.status == "finished"
    (row,) = export(srv.out, tmp_path / "s.csv")
    assert row["final_video_watched"] == "ended" and 0 < float(row["final_video_seconds"]) < 60
    assert row["pid"] == "P-leak-01" and row["condition"] == "cond-secret"


def test_the_participant_code_field_works_without_a_link_id(live_server, page):
    # a study that needs an ID, opened without ?pid=: the participant types it
    study = StudyFile(consent="Agree?", require_pid=True,
                      conditions=[{"name": "c", "method": "bayes-preference"}])
    srv = live_server("bayes-preference", rounds=1, seed=1, study_file=study, video_size=(64, 64))
    page.goto(srv.url + "/")
    page.wait_for_selector("#participant:visible")
    assert page.is_disabled("#begin")
    page.fill("#participant", "bad id!")
    assert page.is_disabled("#begin") and "1 to 64" in page.inner_text("#status")
    page.fill("#participant", "P-typed-9")
    assert page.is_enabled("#begin")
    page.click("#begin")
    page.wait_for_selector("#start:enabled")
    session = srv.manager.get(session_id(page))
    assert session.enrolment.pid == "P-typed-9" and session.participant == "P-typed-9"
    # without a study file: an optional code, typed or not
    plain = live_server("bayes-preference", rounds=1, seed=1, video_size=(64, 64))
    enter(page, plain.url + "/", "P-code-3")
    assert plain.manager.get(session_id(page)).participant == "P-code-3"


def test_a_refused_start_reads_as_a_message_for_participants(live_server, page):
    srv = live_server("bayes-preference", rounds=1, seed=1, video_size=(64, 64),
                      limits={"max_sessions_per_client": 1})
    import httpx

    assert httpx.post(f"{srv.url}/api/sessions", json={}).status_code == 201  # this address's one slot
    enter(page, srv.url + "/", "P-second")
    page.click("#start")
    page.wait_for_selector("#status-how.error")
    text = page.inner_text("#status-how")
    assert "already has a study session open" in text
    assert "limit" not in text and "per client" not in text  # not the server's sentence
    assert page.is_enabled("#start")


def test_ready_waits_for_the_whole_video_so_playback_cannot_stall(live_server, page, tmp_path):
    """A slow video route: Ready stays disabled, showing how much has loaded, until the round's
    video is in the page whole; after Ready it plays from memory (no stall)."""
    srv = live_server("bayes-stop", rounds=1, seed=4, video_size=(64, 64))
    held = []
    page.route("**/files/round1_y.*", lambda r: held.append(r))  # answered later, by the test
    enter(page, srv.url + "/", "P-slow")
    page.click("#start")
    page.wait_for_url("**/signal/stop?session=*")
    sid = session_id(page)
    wait_round(page, 1)
    page.wait_for_timeout(1500)
    assert held, "the video was never requested"
    assert page.is_disabled("#ready") and page.inner_text("#ready").startswith("Loading")
    for route in held:
        route.fulfill(response=route.fetch())
    page.unroute("**/files/round1_y.*")
    page.wait_for_selector("#ready:enabled")
    assert page.inner_text("#ready").startswith("Ready")
    page.click("#ready")
    page.wait_for_function("document.getElementById('video').currentTime > 0")
    assert page.evaluate("document.getElementById('video').currentSrc").startswith("blob:")
    page.click("#new-scene")
    page.wait_for_url("**/done?session=*")
    assert srv.manager.get(sid).join(60)
    page.wait_for_timeout(1200)  # the page's event batch
    (row,) = export(srv.out, tmp_path / "slow.csv")
    assert int(row["round1_stalls"]) == 0, row
    loaded = [e for e in events_of(srv.session_dir(sid)) if e["type"] == "videos_loaded" and e["round"] == 1]
    assert loaded and loaded[0]["data"]["seconds"][0] >= 1.0  # the wait the participant saw, on record


def test_a_stalled_video_is_recorded_per_round_and_exported(live_server, page, tmp_path):
    """When the whole-video load fails the page plays the video as it arrives; a throttled route
    then holds it back until after Ready, so playback waits for it (a stall at t = 0, as on a
    slow connection); the export has the stall and its length."""
    srv = live_server("bayes-stop", rounds=1, seed=4, video_size=(64, 64))
    seen, held = [], []

    def route(r):
        seen.append(r)
        if len(seen) == 1:
            r.abort()  # the whole-video load fails
        else:
            held.append(r)  # the streamed one: answered later, by the test

    page.route("**/files/round1_y.*", route)
    enter(page, srv.url + "/", "P-stall")
    page.click("#start")
    page.wait_for_url("**/signal/stop?session=*")
    sid = session_id(page)
    wait_round(page, 1)
    page.wait_for_selector("#ready:enabled")
    page.click("#ready")
    page.wait_for_timeout(1500)  # playback asked for, no frames: stalled
    assert held, "the video was never requested as a stream"
    for r in held:
        r.fulfill(response=r.fetch())
    page.unroute("**/files/round1_y.*")
    page.wait_for_function("document.getElementById('video').currentTime > 0")
    page.click("#new-scene")
    page.wait_for_url("**/done?session=*")
    session = srv.manager.get(sid)
    assert session.join(60)
    page.wait_for_timeout(1200)  # the page's event batch
    (row,) = export(srv.out, tmp_path / "stall.csv")
    assert int(row["round1_stalls"]) >= 1 and float(row["round1_stall_s"]) >= 1.0, row
    assert any(e["type"] == "videos_load_failed" and e["round"] == 1 for e in events_of(srv.session_dir(sid)))
