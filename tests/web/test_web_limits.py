"""Session limits on a live server: per client address, in all, per hour, and the idle timeout
that frees an abandoned session's slot. Time is a fake clock moved by the test, never a sleep."""

from __future__ import annotations

import json
import time

import httpx
import pytest
from typer.testing import CliRunner

from activeintent.cli import app as cli
from activeintent.web import transport

pytestmark = pytest.mark.slow  # real episodes


def client(address: str) -> httpx.Client:
    """A client whose requests come from ``address`` (any 127.x.y.z is loopback on Linux)."""
    return httpx.Client(transport=httpx.HTTPTransport(local_address=address), timeout=60)


def waiting(c: httpx.Client, url: str, sid: str, timeout: float = 180) -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        s = c.get(f"{url}/api/sessions/{sid}").json()
        assert s["status"] not in ("failed", "cancelled"), s["error"]
        if s["status"] == "waiting-for-answer":
            return s
        time.sleep(0.05)
    raise AssertionError(f"session {sid} never asked")


def error(res: httpx.Response) -> dict:
    err = res.json()["error"]
    assert err["status"] == res.status_code
    return err


def test_idle_sessions_are_cancelled_and_free_their_slots(live_server, fake_clock):
    clock = fake_clock
    srv = live_server("bayes-stop", rounds=2, seed=1, video_size=(64, 64), max_sessions=2, clock=clock,
                      limits={"max_sessions_per_client": 1, "idle_timeout": 60})
    api = f"{srv.url}/api"
    with client("127.0.0.1") as a, client("127.0.0.2") as b, client("127.0.0.3") as c:
        sa = a.post(f"{api}/sessions").json()["id"]
        again = a.post(f"{api}/sessions")
        assert again.status_code == 429 and error(again)["code"] == "too_many_sessions"
        sb = b.post(f"{api}/sessions").json()["id"]
        waiting(a, srv.url, sa)
        waiting(b, srv.url, sb)
        full = c.post(f"{api}/sessions")
        assert full.status_code == 503 and error(full)["code"] == "server_full"

        clock.advance(45)
        assert b.get(f"{api}/sessions/{sb}").status_code == 200  # b's page still polls
        clock.advance(30)  # a: 75 s without a request; b: 30 s
        new = c.post(f"{api}/sessions")
        assert new.status_code == 201, new.text  # a's slot was freed for it

        state_a = b.get(f"{api}/sessions/{sa}").json()
        assert state_a["status"] == "cancelled" and "idle timeout" in state_a["error"]
        assert b.get(f"{api}/sessions/{sb}").json()["status"] == "waiting-for-answer"
        late = a.post(f"{api}/sessions/{sa}/answer", json={"kind": "stop", "round": 1, "action": "no_stop"})
        assert late.status_code == 409 and "cancelled" in error(late)["message"]
        log = [json.loads(x) for x in (srv.session_dir(sa) / "events.jsonl").read_text().splitlines()]
        assert log[-1]["type"] == "session_cancelled" and "idle" in log[-1]["reason"]
        # a may start again once a slot is free: b and c hold both now
        assert a.post(f"{api}/sessions").status_code == 503


def test_a_polled_session_is_not_idle(live_server, fake_clock):
    clock = fake_clock
    srv = live_server("bayes-stop", rounds=1, seed=2, video_size=(64, 64), clock=clock,
                      limits={"idle_timeout": 60})
    sid = httpx.post(f"{srv.url}/api/sessions").json()["id"]
    for _ in range(5):  # five minutes of a page that polls every 50 s
        clock.advance(50)
        assert httpx.get(f"{srv.url}/api/sessions/{sid}").status_code == 200
        assert srv.limits.expire_idle() == []
    clock.advance(61)
    assert [s.id for s in srv.limits.expire_idle()] == [sid]
    assert srv.limits.expire_idle() == []  # cancelled once
    assert srv.manager.get(sid).join(120)


def test_a_client_may_start_only_so_many_sessions_per_hour(live_server, fake_clock):
    clock = fake_clock
    srv = live_server("bayes-stop", rounds=1, seed=3, video_size=(64, 64), max_sessions=4, clock=clock,
                      limits={"max_new_sessions_per_hour": 2, "max_sessions_per_client": 4, "idle_timeout": 7200})
    api = f"{srv.url}/api"
    assert [httpx.post(f"{api}/sessions").status_code for _ in range(2)] == [201, 201]
    clock.advance(1800)
    third = httpx.post(f"{api}/sessions")
    assert third.status_code == 429 and error(third)["code"] == "session_rate_limited"
    assert 1700 <= int(third.headers["retry-after"]) <= 1800
    clock.advance(1801)
    assert httpx.post(f"{api}/sessions").status_code == 201


def test_serve_options_set_the_limits(tmp_path, monkeypatch):
    served = {}
    monkeypatch.setattr(transport, "serve", lambda app, **kw: served.update(app=app, **kw))
    res = CliRunner().invoke(cli, [
        "serve", "--method", "bayes-stop", "--llm", "none", "--out", str(tmp_path / "study"),
        "--max-sessions", "3", "--max-sessions-per-client", "1", "--max-new-sessions-per-hour", "7",
        "--idle-timeout", "2.5", "--max-request-kb", "8", "--events-quota-mb", "0.5",
        "--header-timeout", "4", "--body-timeout", "6", "--max-connections-per-client", "5", "--max-connections", "50",
    ])
    assert res.exit_code == 0, res.output
    limits = served["app"].state.limits
    assert limits.max_sessions == 3 and served["app"].state.manager.config.max_sessions == 3
    assert limits.limits.max_sessions_per_client == 1 and limits.limits.max_new_sessions_per_hour == 7
    assert limits.limits.idle_timeout == 150.0
    assert limits.limits.max_body_bytes == 8 * 1024 and limits.limits.events_quota_bytes == 512 * 1024
    assert limits.limits.body_timeout == 6.0
    connections = served["app"].state.connections
    assert connections.header_timeout == 4.0 and connections.per_client == 5
    assert connections.max_connections <= 50  # and below the file-descriptor limit
    for bad in (["--max-sessions-per-client", "0"], ["--idle-timeout", "0"], ["--max-request-kb", "0"],
                ["--header-timeout", "0"], ["--max-connections-per-client", "0"], ["--max-connections", "2"]):
        res = CliRunner().invoke(cli, ["serve", "--method", "bayes-stop", "--out", str(tmp_path / "x"), *bad])
        assert res.exit_code != 0, bad
    assert not (tmp_path / "x").exists()


def test_a_session_takes_its_slot_at_start_and_a_closed_page_frees_it(live_server, fake_clock):
    """Agreeing only enrols (no slot, no episode); Start takes the slot; a page's beacon on unload
    frees it after the reconnect grace unless a page of the session asks again."""
    clock = fake_clock
    srv = live_server("bayes-stop", rounds=2, seed=1, video_size=(64, 64), clock=clock,
                      limits={"max_sessions_per_client": 1, "idle_timeout": 600, "reconnect_grace": 20})
    api = f"{srv.url}/api"
    with client("127.0.0.1") as a:
        first = a.post(f"{api}/sessions", json={"start": False}).json()
        second = a.post(f"{api}/sessions", json={"start": False}).json()
        assert first["status"] == second["status"] == "enrolled"  # two agreed: neither holds the slot
        assert not srv.manager.get(first["id"]).running
        started = a.post(f"{api}/sessions/{first['id']}/start")
        assert started.status_code == 200 and started.json()["status"] != "enrolled"
        refused = a.post(f"{api}/sessions/{second['id']}/start")
        assert refused.status_code == 429 and error(refused)["code"] == "too_many_sessions"
        waiting(a, srv.url, first["id"])

        # a reload (or the next page): the beacon, then a request of a page within the grace
        assert a.post(f"{api}/sessions/{first['id']}/leave").status_code == 204
        clock.advance(10)
        a.get(f"{api}/sessions/{first['id']}")
        clock.advance(15)
        srv.limits.expire_idle()
        assert srv.manager.get(first["id"]).running
        # the tab closed: nothing comes back within the grace
        assert a.post(f"{api}/sessions/{first['id']}/leave").status_code == 204
        clock.advance(21)
        again = a.post(f"{api}/sessions/{second['id']}/start")
        assert again.status_code == 200, again.text  # the closed page's slot is free again
        gone = srv.manager.get(first["id"])
        assert gone.join(30) and gone.status == "cancelled" and "page closed" in gone.error
        # a stranger's beacon (no key) changes nothing
        with client("127.0.0.2") as b:
            assert b.post(f"{api}/sessions/{second['id']}/leave").status_code == 403


def test_shared_lab_addresses_are_not_limited_per_client(live_server, fake_clock):
    srv = live_server("bayes-stop", rounds=1, seed=1, video_size=(64, 64), clock=fake_clock, max_sessions=3,
                      limits={"max_sessions_per_client": 1, "max_new_sessions_per_hour": 1,
                              "shared_clients": ["127.0.5.0/24"]})
    api = f"{srv.url}/api"
    with client("127.0.5.7") as lab:  # three lab PCs behind one address
        for _ in range(3):
            assert lab.post(f"{api}/sessions").status_code == 201
        full = lab.post(f"{api}/sessions")
        assert full.status_code == 503 and error(full)["code"] == "server_full"  # the server's own limit stays
    with client("127.0.0.9") as other:
        assert error(other.post(f"{api}/sessions"))["code"] == "server_full"
