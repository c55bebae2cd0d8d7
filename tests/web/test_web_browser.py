"""Participants' sessions in a real browser (Debian's Chromium driven by Playwright) against a
live study server; the saved logs must hold the signals the clicks meant.

Screenshots of every page are taken into the test's folder; with
ACTIVEINTENT_UPDATE_SCREENSHOTS=1 they are also copied to docs/img/webapp-*.png.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import pytest

from activeintent.records import read_rounds
from activeintent.sim.env import SimConfig

DOCS_IMG = Path(__file__).resolve().parents[2] / "docs" / "img"

pytestmark = pytest.mark.slow  # a browser and whole episodes


def shot(page, tmp_path: Path, name: str) -> Path:
    path = tmp_path / f"webapp-{name}.png"
    page.screenshot(path=str(path), full_page=True)
    assert path.stat().st_size > 10_000 and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    if os.environ.get("ACTIVEINTENT_UPDATE_SCREENSHOTS") == "1":
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


def start(page, url: str, participant: str, tmp_path: Path | None = None) -> str:
    page.goto(url + "/")
    page.wait_for_selector("#start:enabled")
    page.fill("#participant", participant)
    if tmp_path is not None:
        shot(page, tmp_path, "start")
    page.click("#start")
    page.wait_for_url("**/*?session=*")
    return session_id(page)


def test_two_round_preference_session(live_server, page, tmp_path):
    srv = live_server("bayes-preference", rounds=2, seed=3)
    sid = start(page, srv.url, "P-pref", tmp_path)
    assert urlsplit(page.url).path == "/preference"

    wait_round(page, 1)
    wait_videos(page, "video-a", "video-b")
    assert page.inner_text("#progress .label") == "Round 1 of 2"
    assert page.is_visible("#estimate")  # z is shown (the study's default)
    for v in ("video-a", "video-b"):  # autoplaying, looping videos
        assert page.evaluate(f"document.getElementById('{v}').loop")
    page.wait_for_function("document.getElementById('video-a').currentTime > 0")
    shot(page, tmp_path, "preference")
    page.click('button[data-choice="A"]')

    wait_round(page, 2)
    assert page.inner_text("#progress .label") == "Round 2 of 2"
    page.click('button[data-choice="cant_choose"]')

    page.wait_for_url("**/done?session=*")
    page.wait_for_selector("#question:not(.hidden)")
    wait_videos(page, "final")
    shot(page, tmp_path, "thank-you")
    assert "Thank you" in page.inner_text("#thanks")

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
    srv = live_server("bayes-stop", rounds=2, seed=4)
    sid = start(page, srv.url, "P-stop")
    assert urlsplit(page.url).path == "/clicker"
    folder = srv.session_dir(sid)

    wait_round(page, 1)
    wait_videos(page, "video")
    assert not page.evaluate("document.getElementById('video').loop")  # plays once
    video = srv.manager.get(sid).state()["question"]["videos"][0]
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
    assert page.is_disabled("#good")  # not before the video has ended
    page.evaluate(
        "() => { const v = document.getElementById('video'); v.currentTime = Math.max(0, v.duration - 0.3); v.play(); }"
    )
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
    assert [e["data"]["via"] for e in log if e["type"] == "looks_good"] == ["click"]
    answers = [e for e in log if e["type"] == "answer" and e["source"] == "server"]
    assert [a["answer"] for a in answers] == [h1, h2]
