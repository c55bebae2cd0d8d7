"""The study server's JSON API against a live uvicorn server: good answers become h, every bad
input gets a 4xx with a clear message and leaves the saved data untouched."""

from __future__ import annotations

import http.client
import json
import time
from pathlib import Path
from urllib.parse import urlsplit

import httpx
import pytest
from imageio_ffmpeg import count_frames_and_secs

from activeintent.records import read_rounds

pytestmark = pytest.mark.slow  # real episodes: simulator, video export


def wait_for(predicate, timeout: float = 180.0, what: str = "condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def waiting_state(url: str, sid: str, round: int) -> dict:
    """The state once ``round`` is on screen and its videos are complete (a round is shown while
    its videos are still drawn: until then their files grow)."""
    def ready():
        s = httpx.get(f"{url}/api/sessions/{sid}").json()
        assert s["status"] not in ("failed", "cancelled"), s["error"]
        if s["status"] != "waiting-for-answer" or s["question"]["round"] != round:
            return None
        return s if all(v["complete"] for v in s["question"]["videos"]) else None

    return wait_for(ready, what=f"round {round} of session {sid}")


def snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def raw_get(url: str, path: str) -> tuple[int, str]:
    """GET with the path sent byte for byte (no client-side normalisation of ../)."""
    parts = urlsplit(url)
    conn = http.client.HTTPConnection(parts.hostname, parts.port, timeout=30)
    try:
        conn.request("GET", path)
        res = conn.getresponse()
        return res.status, res.read().decode(errors="replace")
    finally:
        conn.close()


def test_preference_api_accepts_a_valid_answer_and_rejects_bad_ones(live_server, http):
    srv = live_server("bayes-preference", rounds=2, seed=5, video_size=(128, 128))
    api = f"{srv.url}/api"
    created = http.post(f"{api}/sessions", json={"participant": "api-test"})
    assert created.status_code == 201
    sid = created.json()["id"]
    state = waiting_state(srv.url, sid, 1)
    assert state["page"] == "/signal/preference" and state["rounds"] == 2 and state["progress"] == 1
    assert "method" not in state and "intention" not in state  # nothing a participant could read their condition in
    assert [v["label"] for v in state["question"]["videos"]] == ["A", "B"]
    assert state["estimate"] is None  # hidden by default, and never before the first answer
    for v in state["question"]["videos"]:
        res = httpx.get(srv.url + v["url"])
        assert res.status_code == 200 and res.headers["content-type"] == "video/webm"
        assert res.content[:4] == b"\x1a\x45\xdf\xa3"  # EBML: a WebM file
        # the page's duration and frame count are the real file's
        frames, secs = count_frames_and_secs(str(srv.session_dir(sid) / v["file"]))
        assert frames == v["frames"] and secs == pytest.approx(v["duration"], abs=0.02)
    folder = srv.session_dir(sid)
    before = snapshot(folder)
    answer = f"{api}/sessions/{sid}/answer"

    bad = [
        ({"kind": "preference", "round": 1, "choice": "C"}, 422, "'A', 'B', 'cant_choose' or 'new_scene'"),
        ({"kind": "preference", "round": 1}, 422, "choice: Field required"),
        ({"kind": "preference", "choice": "A"}, 422, "round: Field required"),
        ({"kind": "preference", "round": 0, "choice": "A"}, 422, "greater than or equal to 1"),
        ({"kind": "preference", "round": "one", "choice": "A"}, 422, "round"),
        ({"kind": "vote", "round": 1, "choice": "A"}, 422, "'preference', 'stop'"),
        ({"kind": "stop", "round": 1, "action": "no_stop"}, 422, "asks for preference answers"),
        ({"kind": "preference", "round": 2, "choice": "A"}, 409, "waiting for round 1"),
        ([1, 2, 3], 422, "invalid request"),
    ]
    for body, status, message in bad:
        res = http.post(answer, json=body)
        assert res.status_code == status, (body, res.text)
        assert message in res.json()["error"]["message"], (body, res.json())
    res = http.post(answer, content=b"{not json", headers={"content-type": "application/json"})
    assert res.status_code == 422 and "JSON" in res.json()["error"]["message"]
    assert snapshot(folder) == before, "a rejected answer changed the saved data"

    ok = http.post(answer, json={"kind": "preference", "round": 1, "choice": "B", "client_ts": 1.0})
    assert ok.status_code == 200 and ok.json()["answer"]["choice"] == "B"
    rounds = wait_for(lambda: read_rounds(folder / "rounds.jsonl"), what="rounds.jsonl")
    assert rounds[0]["answer"] == {"signal": "preference", "new_scene": False, "choice": "B"}

    # the same answer again (a replay) is refused and the log keeps one round
    after = snapshot(folder)
    replay = http.post(answer, json={"kind": "preference", "round": 1, "choice": "A"})
    assert replay.status_code == 409
    assert "round 1" in replay.json()["error"]["message"]
    waiting_state(srv.url, sid, 2)
    replay = http.post(answer, json={"kind": "preference", "round": 1, "choice": "A"})
    assert replay.status_code == 409 and "waiting for round 2" in replay.json()["error"]["message"]
    assert read_rounds(folder / "rounds.jsonl") == rounds
    assert (folder / "rounds.jsonl").read_bytes() == after["rounds.jsonl"]

    # result only once finished
    res = httpx.get(f"{api}/sessions/{sid}/result")
    assert res.status_code == 409 and "no result yet" in res.json()["error"]["message"]


def test_stop_api_maps_times_and_rejects_times_outside_the_video(live_server, http):
    srv = live_server("bayes-stop", rounds=1, seed=2, video_size=(128, 128))
    api = f"{srv.url}/api"
    sid = http.post(f"{api}/sessions").json()["id"]
    state = waiting_state(srv.url, sid, 1)
    video = state["question"]["videos"][0]
    assert video["fps"] == 10 and video["frames"] >= 2
    assert video["duration"] == pytest.approx(video["frames"] / video["fps"])
    folder = srv.session_dir(sid)
    before = snapshot(folder)
    answer = f"{api}/sessions/{sid}/answer"
    outside = [-0.5, video["duration"] + 0.5, 1e9]
    for t in outside:
        res = http.post(answer, json={"kind": "stop", "round": 1, "action": "stop", "time": t})
        assert res.status_code == 422 and "outside the video" in res.json()["error"]["message"], res.text
    for raw in (b"NaN", b"Infinity", b"-Infinity", b'"soon"'):
        body = b'{"kind": "stop", "round": 1, "action": "stop", "time": ' + raw + b"}"
        res = http.post(answer, content=body, headers={"content-type": "application/json"})
        assert res.status_code == 422, (raw, res.text)
        assert "time" in res.json()["error"]["message"]
    for body, message in [
        ({"kind": "stop", "round": 1, "action": "stop"}, "needs 'time'"),
        ({"kind": "stop", "round": 1, "action": "no_stop", "time": 1.0}, "takes no 'time'"),
        ({"kind": "stop", "round": 1, "action": "halt", "time": 1.0}, "'stop', 'no_stop' or 'new_scene'"),
        ({"kind": "preference", "round": 1, "choice": "A"}, "asks for stop answers"),
    ]:
        res = http.post(answer, json=body)
        assert res.status_code == 422 and message in res.json()["error"]["message"], (body, res.text)
    assert snapshot(folder) == before

    t = 0.45  # media time → trajectory time 0.45 s: frame 4, tick round(0.45 / dt)
    res = http.post(answer, json={"kind": "stop", "round": 1, "action": "stop", "time": t})
    assert res.status_code == 200, res.text
    h = res.json()["answer"]
    assert h["stop_time"] == pytest.approx(t) and h["frame"] == 4
    session = srv.manager.get(sid)
    assert session.join(300), "the episode did not finish"
    assert session.status == "finished", session.error
    rounds = read_rounds(folder / "rounds.jsonl")
    assert len(rounds) == 1 and rounds[0]["answer"] == h
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["method"] == "bayes-stop" and summary["signals_used"] == 1
    result = httpx.get(f"{api}/sessions/{sid}/result").json()
    assert result["signals_used"] == 1 and not {"method", "intention", "final_z", "seed"} & set(result)
    assert (folder / "final.webm").stat().st_size > 0 and (folder / "round1_y.webm").exists()
    import imageio.v2 as iio

    for name in ("round1_y", "final"):  # an H.264 MP4 beside each WebM, the same frames
        mp4, webm = iio.get_reader(folder / f"{name}.mp4"), iio.get_reader(folder / f"{name}.webm")
        assert mp4.get_meta_data()["codec"] == "h264"
        assert mp4.count_frames() == webm.count_frames() and mp4.count_frames() >= 2
    assert video["mp4_url"].endswith("/round1_y.mp4")
    res = http.get(srv.url + video["mp4_url"])
    assert res.status_code == 200 and res.headers["content-type"] == "video/mp4"
    assert res.content == (folder / "round1_y.mp4").read_bytes()

    # a finished session takes no answers; its saved data stays as it is
    done = snapshot(folder)
    res = http.post(answer, json={"kind": "stop", "round": 2, "action": "no_stop"})
    assert res.status_code == 409 and "finished" in res.json()["error"]["message"]
    assert snapshot(folder) == done


def test_unknown_sessions_path_traversal_and_isolation(live_server, http):
    srv = live_server("bayes-preference", rounds=2, seed=1, max_sessions=2, video_size=(128, 128),
                      limits={"max_sessions_per_client": 3})
    api = f"{srv.url}/api"
    a = http.post(f"{api}/sessions").json()["id"]
    b = http.post(f"{api}/sessions").json()["id"]
    assert a != b
    full = http.post(f"{api}/sessions")
    assert full.status_code == 503 and "limit 2" in full.json()["error"]["message"]
    assert full.json()["error"]["code"] == "server_full" and int(full.headers["retry-after"]) > 0
    waiting_state(srv.url, a, 1)
    waiting_state(srv.url, b, 1)
    before_b = snapshot(srv.session_dir(b))

    # answering session a leaves session b waiting for its own round 1
    res = http.post(f"{api}/sessions/{a}/answer", json={"kind": "preference", "round": 1, "choice": "A"})
    assert res.status_code == 200
    waiting_state(srv.url, a, 2)
    state_b = httpx.get(f"{api}/sessions/{b}").json()
    assert state_b["question"]["round"] == 1 and state_b["rounds_answered"] == 0
    assert snapshot(srv.session_dir(b)) == before_b

    for sid in ("0123456789abcdef", "nope", a.upper(), a + "0"):
        for method, path, body in [
            ("GET", f"/sessions/{sid}", None),
            ("POST", f"/sessions/{sid}/answer", {"kind": "preference", "round": 1, "choice": "A"}),
            ("POST", f"/sessions/{sid}/events", {"events": [{"type": "x", "client_ts": 1}]}),
            ("GET", f"/sessions/{sid}/result", None),
            ("POST", f"/sessions/{sid}/questionnaire", {"final_attempt": "yes", "rule": "mine"}),
        ]:
            res = http.request(method, api + path, json=body)
            assert res.status_code == 404, (method, path, res.text)
            assert "unknown session" in res.json()["error"]["message"]

    # only this session's videos are served: no other files, no other folders
    ok, _ = raw_get(srv.url, f"/api/sessions/{a}/files/round1_a.webm")
    assert ok == 200
    secret = srv.out.parent / "secret.txt"
    secret.write_text("not for participants")
    attempts = [
        f"/api/sessions/{a}/files/summary.json",
        f"/api/sessions/{a}/files/events.jsonl",
        f"/api/sessions/{a}/files/session.json",
        f"/api/sessions/{a}/files/questionnaire.json",
        f"/api/sessions/{a}/files/../{b}/round1_a.webm",
        f"/api/sessions/{a}/files/..%2F{b}%2Fround1_a.webm",
        f"/api/sessions/{a}/files/%2e%2e%2f{b}%2fround1_a.webm",
        f"/api/sessions/{a}/files/%252e%252e%252f{b}%252fround1_a.webm",
        f"/api/sessions/{a}/files/..%5c{b}%5cround1_a.webm",
        f"/api/sessions/{a}/files/..%2F..%2Fsecret.txt",
        f"/api/sessions/{a}/files/%2e%2e/%2e%2e/secret.txt",
        f"/api/sessions/{a}/files/.%2e/.%2e/secret.txt",
        "/static/../../secret.txt",
        "/static/..%2F..%2F..%2Fpyproject.toml",
        "/static/%2e%2e/server.py",
        "/static/%2e%2e/%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
    ]
    for path in attempts:
        status, text = raw_get(srv.url, path)
        assert status in (400, 404), (path, status)
        assert "not for participants" not in text and "root:" not in text and "import" not in text

    # the events of a session go to its own events.jsonl only
    res = http.post(f"{api}/sessions/{b}/events",
                     json={"events": [{"type": "probe", "client_ts": 1234.5, "round": 1, "data": {"k": 1}}]})
    assert res.status_code == 200 and res.json() == {"logged": 1}
    events_b = [json.loads(x) for x in (srv.session_dir(b) / "events.jsonl").read_text().splitlines()]
    events_a = [json.loads(x) for x in (srv.session_dir(a) / "events.jsonl").read_text().splitlines()]
    probe = [e for e in events_b if e["type"] == "probe"]
    assert len(probe) == 1 and probe[0]["client_ts"] == 1234.5 and probe[0]["server_ts"] > 0
    assert not [e for e in events_a if e["type"] == "probe"]
    for body in ({"events": []}, {"events": [{"type": "", "client_ts": 1}]},
                 {"events": [{"type": "x", "client_ts": 1, "data": {"blob": "x" * 5000}}]}):
        res = http.post(f"{api}/sessions/{b}/events", json=body)
        assert res.status_code == 422, res.text


def test_openapi_describes_the_api(live_server):
    srv = live_server("bayes-stop", rounds=1)
    spec = httpx.get(f"{srv.url}/openapi.json").json()
    paths = set(spec["paths"])
    assert {"/api/config", "/api/sessions", "/api/sessions/{sid}", "/api/sessions/{sid}/answer",
            "/api/sessions/{sid}/events", "/api/sessions/{sid}/result", "/api/sessions/{sid}/questionnaire",
            "/api/sessions/{sid}/final-video", "/api/sessions/{sid}/files/{name}"} <= paths
    config = httpx.get(f"{srv.url}/api/config").json()
    assert config == {"study": False, "consent": None, "require_pid": False,
                      "url_parameters": ["pid", "PROLIFIC_PID", "STUDY_ID", "SESSION_ID"], "rounds": 1, "design": "free-rule",
                      "intention_description": None, "show_estimate": "hidden", "fps": 10,
                      "video_size": [800, 600]}


def test_stopping_the_server_cancels_sessions_in_progress(live_server, http):
    srv = live_server("bayes-stop", rounds=2, seed=6, video_size=(128, 128))
    sid = http.post(f"{srv.url}/api/sessions").json()["id"]
    waiting_state(srv.url, sid, 1)
    srv.manager.shutdown(timeout=60)  # what the app's lifespan does when uvicorn stops
    session = srv.manager.get(sid)
    assert not session.active and session.status == "cancelled" and "server stopped" in session.error
    res = http.post(f"{srv.url}/api/sessions/{sid}/answer", json={"kind": "stop", "round": 1, "action": "no_stop"})
    assert res.status_code == 409 and "cancelled" in res.json()["error"]["message"]
    log = [json.loads(x) for x in (srv.session_dir(sid) / "events.jsonl").read_text().splitlines()]
    assert log[-1]["type"] == "session_cancelled"
    assert read_rounds(srv.session_dir(sid) / "rounds.jsonl") == []


def test_request_bodies_take_exact_types_not_lookalikes(live_server):
    """``{"seed": true}`` is not seed 1, ``"yes"`` is not consent and ``1.0`` is not round 1:
    each is a 422 naming the field, and nothing is started or stored."""
    srv = live_server("bayes-stop", rounds=1, seed=4, video_size=(64, 64))
    api = f"{srv.url}/api"
    with httpx.Client(timeout=60) as http:
        for body, field in [({"seed": True}, "seed"), ({"seed": False}, "seed"), ({"seed": 1.0}, "seed"),
                            ({"seed": "3"}, "seed"), ({"participant": 7}, "participant"),
                            ({"consent": "yes"}, "consent"), ({"consent": 1}, "consent"), ({"pid": 12345}, "pid")]:
            res = http.post(f"{api}/sessions", json=body)
            assert res.status_code == 422, (body, res.text)
            err = res.json()["error"]
            assert err["code"] == "invalid_request" and field in [f["loc"] for f in err["fields"]], (body, err)
        assert srv.manager.all() == [], "a refused request started a session"
        created = http.post(f"{api}/sessions", json={"seed": 3})
        assert created.status_code == 201, created.text
        sid = created.json()["id"]
        assert srv.manager.get(sid).seed == 3
        waiting_state(srv.url, sid, 1)
        folder = srv.session_dir(sid)
        before = snapshot(folder)
        lookalikes = [
            ("answer", {"kind": "stop", "round": True, "action": "no_stop"}, "round"),
            ("answer", {"kind": "stop", "round": 1.0, "action": "no_stop"}, "round"),
            ("answer", {"kind": "stop", "round": "1", "action": "no_stop"}, "round"),
            ("answer", {"kind": "stop", "round": 1, "action": "stop", "time": True}, "time"),
            ("answer", {"kind": "stop", "round": 1, "action": "no_stop", "client_ts": True}, "client_ts"),
            ("events", {"events": [{"type": "x", "client_ts": True}]}, "client_ts"),
            ("events", {"events": [{"type": "x", "client_ts": 1.5, "round": True}]}, "round"),
            ("video", {"round": True, "event": "ready"}, "round"),
            ("video", {"round": 1, "event": "ready", "media_time": False}, "media_time"),
        ]
        for path, body, field in lookalikes:
            res = http.post(f"{api}/sessions/{sid}/{path}", json=body)
            assert res.status_code == 422, (path, body, res.text)
            err = res.json()["error"]
            assert err["code"] == "invalid_request" and any(f["loc"].endswith(field) for f in err["fields"]), err
        assert snapshot(folder) == before, "a refused request changed the saved data"
        # whole numbers where seconds are asked for are still numbers
        ok = http.post(f"{api}/sessions/{sid}/answer",
                       json={"kind": "stop", "round": 1, "action": "no_stop", "client_ts": 1700000000})
        assert ok.status_code == 200, ok.text


def test_a_session_takes_answers_only_from_the_browser_that_started_it(live_server):
    """The session id is in the page's URL; the key cookie set when the session starts is what
    lets a request answer, and every stored answer says who gave it."""
    import hashlib

    srv = live_server("bayes-stop", rounds=1, seed=7, video_size=(64, 64))
    api = f"{srv.url}/api"

    def client(address: str) -> httpx.Client:
        return httpx.Client(transport=httpx.HTTPTransport(local_address=address), timeout=60)

    with client("127.0.0.1") as owner, client("127.0.0.2") as stranger:
        created = owner.post(f"{api}/sessions", json={"participant": "P-owner"})
        assert created.status_code == 201, created.text
        sid = created.json()["id"]
        (cookie,) = created.headers.get_list("set-cookie")
        attributes = [a.strip().lower() for a in cookie.split(";")]
        name, _, key = attributes[0].partition("=")
        assert name == "activeintent_key" and len(key) >= 43  # 256 random bits, URL-safe base64
        assert "httponly" in attributes and "samesite=strict" in attributes
        assert f"path=/api/sessions/{sid}" in attributes
        key = cookie.split(";")[0].partition("=")[2]
        waiting_state(srv.url, sid, 1)
        folder = srv.session_dir(sid)
        before = snapshot(folder)

        other = stranger.post(f"{api}/sessions", json={"participant": "P-other"}).json()["id"]
        other_key = stranger.cookies.get("activeintent_key", path=f"/api/sessions/{other}")
        no_stop = {"kind": "stop", "round": 1, "action": "no_stop"}
        attempts = [
            (stranger, {}),  # no key at all
            (stranger, {"Cookie": "activeintent_key=" + "A" * 43}),  # a guessed one
            (stranger, {"Cookie": f"activeintent_key={other_key}"}),  # the key of another session
            (httpx, {"Cookie": f"activeintent_key={key[:-1]}"}),  # almost the right one
        ]
        for c, headers in attempts:
            for path, body in [("answer", no_stop), ("video", {"round": 1, "event": "ready"}),
                               ("events", {"events": [{"type": "x", "client_ts": 1.7e9}]}),
                               ("questionnaire", {"final_attempt": "yes", "rule": "mine"}),
                               ("final-video", {"event": "ended"}),
                               ("answer", {"kind": "stop", "round": "bad"})]:  # refused before validation
                res = c.post(f"{api}/sessions/{sid}/{path}", json=body, headers=headers)
                assert res.status_code == 403, (path, headers, res.text)
                err = res.json()["error"]
                assert err["code"] == "not_session_owner" and "browser that started it" in err["message"]
        assert snapshot(folder) == before, "a refused request changed the saved data"
        assert stranger.get(f"{api}/sessions/{sid}").status_code == 200  # reading needs only the id

        ok = owner.post(f"{api}/sessions/{sid}/answer", json=no_stop)
        assert ok.status_code == 200, ok.text
        session = srv.manager.get(sid)
        assert session.join(300) and session.status == "finished", session.error
        owner.post(f"{api}/sessions/{sid}/final-video", json={"event": "ended"}).raise_for_status()
        q = owner.post(f"{api}/sessions/{sid}/questionnaire", json={"final_attempt": "no", "rule": "mine"})
        assert q.status_code == 201, q.text

    key_id = hashlib.sha256(key.encode()).hexdigest()[:16]
    by = {"participant": "P-owner", "key": key_id, "address": "127.0.0.1"}
    info = json.loads((folder / "session.json").read_text())
    assert info["key_id"] == key_id and key not in (folder / "session.json").read_text()
    log = [json.loads(x) for x in (folder / "events.jsonl").read_text().splitlines()]
    assert [e["answered_by"] for e in log if e["type"] == "answer"] == [by]
    assert [r["answered_by"] for r in read_rounds(folder / "rounds.jsonl")] == [by]
    assert json.loads((folder / "questionnaire.json").read_text())["answered_by"] == by
    assert all(key not in p.read_text(errors="replace") for p in folder.iterdir() if p.suffix in (".json", ".jsonl"))
