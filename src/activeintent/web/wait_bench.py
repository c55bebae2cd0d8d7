"""`activeintent web-bench`: how long a participant waits between rounds of the web study.

The wait is what a person sits through after an answer before the next round's videos can be
played: the learner's update and next query, the physics run and the first half second of
every video (the rest is drawn while it plays, ``activeintent.web.live``). It is measured on the real
app (FastAPI with its sessions, episodes and PyBullet, in process, through a test client), so
the figures are the server's part of the wait (a browser adds the download). Each round is
answered as soon as its videos are complete, never earlier than a participant who pressed Ready
at once could have watched them, so no round's drawing is still running when the learner starts
the next; how far the drawing ran ahead of playback is reported too (``ahead_s``: a video's
length minus the time it took to complete; below 0 a participant who pressed Ready at once would
have seen it pause). The first round's wait, from the start of the session, includes loading the
simulator and is reported apart.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from activeintent.learners.registry import get_method
from activeintent.spec import RunSpec

POLL_S = 0.02
READY = ("waiting-for-answer", "finished", "failed", "cancelled")


def _answer(signal: str, round_: int) -> dict:
    if signal == "preference":
        return {"kind": "preference", "round": round_, "choice": "A"}
    return {"kind": "stop", "round": round_, "action": "no_stop"}


def measure_waits(method: str, rounds: int, video_size: tuple[int, int], seed: int, out: Path,
                  intention: str | None = None, timeout_s: float = 900.0) -> dict:
    """Seconds from each answer until the next round (or the end) is ready, for one session."""
    from fastapi.testclient import TestClient

    # lazy: FastAPI loads only when the bench runs
    from activeintent.web.server import create_app, runner_builder
    from activeintent.web.session import StudyConfig

    run = RunSpec.from_options(method=method, budget=rounds, intention=intention, llm="none")
    config = StudyConfig(run=run, signal=get_method(method).signal, out_dir=out, video_size=video_size)
    app = create_app(config, runner_builder(config))
    waits: list[float] = []
    ahead: list[float] = []  # per video: its length minus the seconds until it was complete
    with TestClient(app) as client:
        start = time.perf_counter()
        sid = client.post("/api/sessions", json={"seed": seed, "consent": True}).json()["id"]

        def ready(after: int) -> dict:
            deadline = time.perf_counter() + timeout_s
            while time.perf_counter() < deadline:
                state = client.get(f"/api/sessions/{sid}").json()
                q = state.get("question")
                if state["status"] in READY[1:] or (q is not None and q["round"] > after):
                    return state
                time.sleep(POLL_S)
            raise TimeoutError(f"the session did not get ready within {timeout_s:.0f} s")

        def complete(state: dict, shown: float) -> None:
            videos = state["question"]["videos"]
            deadline = time.perf_counter() + timeout_s
            while not all(v["complete"] for v in videos):
                if time.perf_counter() > deadline:
                    raise TimeoutError(f"the round's videos were not complete within {timeout_s:.0f} s")
                time.sleep(POLL_S)
                videos = client.get(f"/api/sessions/{sid}").json()["question"]["videos"]
            took = time.perf_counter() - shown
            ahead.extend(v["duration"] - took for v in videos)

        state = ready(0)
        first = time.perf_counter() - start
        while state["status"] == "waiting-for-answer":
            r = state["question"]["round"]
            complete(state, time.perf_counter())
            sent = time.perf_counter()
            got = client.post(f"/api/sessions/{sid}/answer", json=_answer(config.signal, r))
            if got.status_code != 200:
                raise RuntimeError(f"the app refused the answer to round {r}: {got.text[:300]}")
            state = ready(r)
            if state["status"] == "waiting-for-answer":
                waits.append(time.perf_counter() - sent)
        if state["status"] != "finished":
            raise RuntimeError(f"the session ended {state['status']}")
    w = np.array(waits)
    return {"method": method, "signal": config.signal, "rounds": rounds, "video_px": list(video_size),
            "first_round_s": round(first, 2), "waits_s": [round(x, 2) for x in waits],
            "ahead_s": [round(x, 2) for x in ahead],
            "p50_s": round(float(np.percentile(w, 50)), 2) if len(w) else None,
            "p90_s": round(float(np.percentile(w, 90)), 2) if len(w) else None,
            "target_p90_s": 3.0}
