"""`activeintent serve`: option errors before anything starts; a real server on loopback."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
import time

import httpx
import pytest
from typer.testing import CliRunner

from activeintent.cli import app


def test_bad_options_fail_before_serving_and_list_the_valid_ones(tmp_path):
    runner = CliRunner()
    res = runner.invoke(app, ["serve", "--method", "clicks", "--out", str(tmp_path)])
    assert res.exit_code != 0
    assert "bayes-preference" in res.output and "mllm-llm" in res.output
    res = runner.invoke(app, ["serve", "--method", "bayes-stop", "--intention", "nonsense", "--out", str(tmp_path)])
    assert res.exit_code != 0 and "color-match" in res.output
    res = runner.invoke(app, ["serve", "--method", "bayes-stop", "--show-estimate", "sometimes", "--out", str(tmp_path)])
    assert res.exit_code != 0 and "after-answer" in res.output
    assert not any(tmp_path.iterdir())  # nothing was started or saved


def test_serve_names_the_design_and_configures_the_study(tmp_path, monkeypatch):
    from activeintent.web import transport

    served = []
    monkeypatch.setattr(transport, "serve", lambda app, **kw: served.append(app))
    runner = CliRunner()
    res = runner.invoke(app, ["serve", "--method", "bayes-stop", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    said = " ".join(res.output.split())  # the console wraps long lines
    assert "free rule" in said and "not scored" in said and "color-match" not in said
    free = served[-1].state.manager.config
    assert free.design == "free-rule" and free.intention_name is None and free.show_estimate == "hidden"
    assert free.video_size == (800, 600)  # every block at least 40 px (tests/sim/test_camera.py)
    assert "model none" in said  # a method that needs no model gets none unless --llm is given
    bad = runner.invoke(app, ["serve", "--method", "bayes-stop", "--video-size", "800x", "--out", str(tmp_path)])
    assert bad.exit_code != 0 and "WIDTHxHEIGHT" in " ".join(bad.output.split())
    lab = runner.invoke(app, ["serve", "--method", "bayes-stop", "--shared-client", "10.1.2.0/24",
                              "--reconnect-grace", "30", "--out", str(tmp_path)])
    assert lab.exit_code == 0, lab.output
    limits = served[-1].state.limits.limits
    assert limits.shared("10.1.2.77") and not limits.shared("10.1.3.1") and limits.reconnect_grace == 30
    wrong = runner.invoke(app, ["serve", "--method", "bayes-stop", "--shared-client", "lab-pc", "--out", str(tmp_path)])
    assert wrong.exit_code != 0 and "not an address or network" in " ".join(wrong.output.split())
    res = runner.invoke(app, ["serve", "--method", "bayes-stop", "--video-size", "640x360", "--out", str(tmp_path)])
    assert res.exit_code == 0 and served[-1].state.manager.config.video_size == (640, 360), res.output
    res = runner.invoke(app, ["serve", "--method", "bayes-preference", "--intention", "color-match",
                              "--show-estimate", "after-answer", "--video-size", "360", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    said = " ".join(res.output.split())
    assert "assigned rule color-match" in said and "Put each block in the bowl of the same colour." in said
    assigned = served[-1].state.manager.config
    assert assigned.design == "assigned-rule" and assigned.intention_name == "color-match"
    assert assigned.show_estimate == "after-answer" and assigned.video_size == (360, 360)
    from pydantic import ValidationError

    from activeintent.spec import RunSpec
    from activeintent.web.session import StudyConfig

    with pytest.raises(ValidationError, match="64-2048"):  # a study built in Python keeps the CLI's rule
        StudyConfig(run=RunSpec.from_options(method="bayes-stop", budget=3), signal="stop", video_size=(32, 4000))


def test_serve_binds_loopback_and_answers(tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    out = tmp_path / "study"
    proc = subprocess.Popen(
        [sys.executable, "-m", "activeintent.cli", "serve", "--port", str(port), "--method", "bayes-stop",
         "--budget", "3", "--show-estimate", "hidden", "--video-size", "128", "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    try:
        config = None
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                config = httpx.get(f"http://127.0.0.1:{port}/api/config", timeout=5).json()
                break
            except httpx.TransportError:
                time.sleep(0.2)
        assert config == {"study": False, "consent": None, "require_pid": False,
                          "url_parameters": ["pid", "PROLIFIC_PID", "STUDY_ID", "SESSION_ID"], "rounds": 3, "design": "free-rule",
                          "intention_description": None, "show_estimate": "hidden",
                          "fps": 10, "video_size": [128, 128]}
        page = httpx.get(f"http://127.0.0.1:{port}/")
        assert page.status_code == 200 and "Teach the robot" in page.text
        listening = [c for c in _tcp_listeners() if c[1] == port]
        assert listening and all(addr == "127.0.0.1" for addr, _ in listening), listening
    finally:
        proc.send_signal(signal.SIGINT)
        output = proc.communicate(timeout=60)[0]
    assert proc.returncode == 0, output
    assert f"http://localhost:{port}/" in output


def _tcp_listeners() -> list[tuple[str, int]]:
    """(address, port) of the IPv4 sockets in LISTEN state, from /proc/net/tcp."""
    found = []
    with open("/proc/net/tcp") as f:
        next(f)
        for line in f:
            local, state = line.split()[1], line.split()[3]
            if state != "0A":
                continue
            hex_addr, hex_port = local.split(":")
            addr = ".".join(str(int(hex_addr[i:i + 2], 16)) for i in (6, 4, 2, 0))
            found.append((addr, int(hex_port, 16)))
    return found


def test_serve_loads_a_study_file(tmp_path, monkeypatch):
    from activeintent.web import transport

    served = []
    monkeypatch.setattr(transport, "serve", lambda app, **kw: served.append(app))
    study = tmp_path / "study.toml"
    study.write_text('consent = "Agree?"\ncompletion_code = "C1"\n\n[[conditions]]\nname = "pref"\n'
                     'method = "bayes-preference"\nintention = "color-match"\n\n[[conditions]]\nname = "stop"\n'
                     'method = "bayes-stop"\nshow_estimate = "always"\n')
    runner = CliRunner()
    res = runner.invoke(app, ["serve", "--study", str(study), "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    manager = served[-1].state.manager
    assert set(manager.conditions) == {"pref", "stop"} and manager.study.completion_code == "C1"
    assert manager.conditions["stop"][0].show_estimate == "always" and manager.conditions["pref"][0].design == "assigned-rule"
    res = runner.invoke(app, ["serve", "--study", str(study), "--method", "bayes-stop", "--out", str(tmp_path)])
    assert res.exit_code != 0 and "set per condition" in res.output
    study.write_text('consent = "x"\n[[conditions]]\nname = "a"\nmethod = "clicks"\n')
    res = runner.invoke(app, ["serve", "--study", str(study), "--out", str(tmp_path)])
    assert res.exit_code != 0 and "bayes-preference" in res.output
