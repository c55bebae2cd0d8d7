"""The human-in-the-loop web app: a JSON API under /api and plain HTML/JS pages.

Pages: ``/`` (start), ``/signal/<name>`` (the signal's own answer page, from the signal's folder:
``preference`` shows two videos, A / B / Can't choose / New scene; ``stop`` one video, Stop /
Looks good / New scene) and ``/done`` (final execution, the end-of-session questionnaire and
thank-you). Each page polls ``GET /api/sessions/{id}`` and
answers with ``POST /api/sessions/{id}/answer`` naming the round it answers; the done page sends
``POST /api/sessions/{id}/questionnaire``.
"""

from __future__ import annotations

import asyncio
import json
import logging
import time
from collections.abc import Callable
from contextlib import asynccontextmanager
from pathlib import Path
from typing import Annotated, Any, Literal, Union

from fastapi import Depends, FastAPI, Request, Response
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import FileResponse, StreamingResponse
from fastapi.staticfiles import StaticFiles
from pydantic import BaseModel, ConfigDict, Field, field_validator

from activeintent.runner import build_episode
from activeintent.signals import SIGNALS, AnswerRejected, Signal, WebForm, get_signal
from activeintent.signals import Answer as SignalAnswer
from activeintent.signals.base import MAX_ROUND
from activeintent.sim.render import warm_render_pool
from activeintent.users.human import Question
from activeintent.web.errors import ApiError, install_error_handlers
from activeintent.web.limits import BodyGuard, Limits, SessionLimits, event_lines_size
from activeintent.web.live import follow
from activeintent.web.session import (
    SERVED_FILE,
    EpisodeBuilder,
    SessionManager,
    StudyConfig,
    WebSession,
    new_session_key,
    signal_page,
)
from activeintent.web.session_view import session_state
from activeintent.web.study import PID_RULE, URL_PARAMETERS, StudyFile, check_pid
from activeintent.web.transport import ConnectionGuard, RequestPhases

STATIC = Path(__file__).parent / "static"
MAX_FILE_NAME = 64  # longer than any video name the server writes
log = logging.getLogger("activeintent.web")
PAGES = {"/": "index.html", "/done": "done.html"}  # and each signal's own page (signal_page)
# The session key: set when a session starts, for that session's API paths only, never readable
# by scripts, never sent by other sites' pages; every request that writes to the session needs it.
KEY_COOKIE = "activeintent_key"
KEY_COOKIE_MAX_AGE = 24 * 3600  # outlives any session and its questionnaire
MAX_KEY_COOKIES = 8  # a request's cookies of that name that are looked at


def key_cookies(request: Request) -> list[str]:
    """The values of the request's session key cookies (a browser sends one per matching path)."""
    values = []
    for header in request.headers.getlist("cookie"):
        for part in header.split(";"):
            name, eq, value = part.strip().partition("=")
            if eq and name == KEY_COOKIE:
                values.append(value.strip().strip('"'))
    return values[:MAX_KEY_COOKIES]


# -- request bodies ---------------------------------------------------------------------------
# Every body forbids fields it does not know and bounds every number: a typo or a probe is a
# 422, never something silently ignored or stored. Types are strict: true is not 1, "yes" is not
# true and 1.0 is not round 1 (pydantic would convert each); a whole number still counts as seconds.
def _client_ts():
    return Field(None, ge=0, le=1e11, allow_inf_nan=False, description="browser clock (s since the epoch)")


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


def _url_id(what: str):
    return Field(None, description=f"{what}, from the study link; {PID_RULE}")


class NewSession(_Body):
    participant: str | None = Field(None, max_length=100, description="optional participant code (typed)")
    seed: int | None = Field(None, ge=0, le=2**31 - 1, description="seed of the episode (default: next)")
    pid: str | None = _url_id("the participant ID (?pid= or PROLIFIC_PID=)")
    study_id: str | None = _url_id("STUDY_ID")
    prolific_session_id: str | None = _url_id("SESSION_ID")
    consent: bool | None = Field(None, description="the participant agreed to the study's consent text")
    start: bool = Field(True, description="start the episode now; false: enrol only (the start page's "
                        "agreement), and POST /api/sessions/{id}/start when the participant presses Start")

    @field_validator("pid", "study_id", "prolific_session_id")
    @classmethod
    def _url_ids(cls, v: str | None, info) -> str | None:
        what = {"pid": "participant ID", "study_id": "STUDY_ID", "prolific_session_id": "SESSION_ID"}[info.field_name]
        return None if v is None else check_pid(v, what)

    @field_validator("participant")
    @classmethod
    def _printable(cls, v: str | None) -> str | None:
        if v is not None and not v.isprintable():
            raise ValueError("the participant code takes printable characters only")
        return v


class VideoReport(_Body):
    round: int = Field(ge=1, le=MAX_ROUND, description="the round on screen")
    event: Literal["ready", "ended", "replay"] = Field(
        description="ready: the first viewing starts; ended: it played to the end; replay: a replay starts")
    media_time: float | None = Field(None, ge=0, le=1e5, allow_inf_nan=False)
    client_ts: float | None = _client_ts()


class FinalVideoReport(_Body):
    event: Literal["ready", "ended", "replay"] = Field(
        description="ready: the final attempt starts; ended: it played to the end; replay: a replay starts")
    media_time: float | None = Field(None, ge=0, le=1e5, allow_inf_nan=False)
    client_ts: float | None = _client_ts()


class ClientEvent(_Body):
    type: str = Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_.:-]+$")
    client_ts: float = Field(ge=0, le=1e11, allow_inf_nan=False,
                             description="the browser's clock, seconds since the epoch")
    round: int | None = Field(None, ge=0, le=MAX_ROUND)
    data: dict[str, Any] = Field(default_factory=dict)

    @field_validator("data")
    @classmethod
    def _small(cls, v: dict) -> dict:
        if len(json.dumps(v, allow_nan=False)) > 4000:
            raise ValueError("event data is limited to 4000 characters of JSON")
        return v


class EventBatch(_Body):
    events: list[ClientEvent] = Field(min_length=1, max_length=200)


MAX_RULE_CHARS = 2000
MAX_COMMENT_CHARS = 4000


def _text(v: str | None, what: str) -> str | None:
    """Free text as people type it: surrounding blanks dropped, line breaks and tabs kept, no
    other control characters."""
    if v is None:
        return None
    v = v.strip()
    if any(not (c.isprintable() or c in "\n\t") for c in v):
        raise ValueError(f"{what} takes printable characters, line breaks and tabs only")
    return v


class QuestionnaireAnswers(_Body):
    final_attempt: Literal["yes", "partly", "no"] | None = Field(
        None, description="did the robot's final attempt do what the participant wanted (required when "
        "the session finished with a final attempt; left out otherwise)")
    rule: str = Field(min_length=1, max_length=MAX_RULE_CHARS,
                      description="the participant's rule in their own words")
    comments: str | None = Field(None, max_length=MAX_COMMENT_CHARS, description="optional comments")
    final_video_watched: Literal["ended", "replayed"] | None = Field(
        None, description="how the page saw the final attempt's video watched before it opened the questions: "
        "played to its end, or replayed by the participant (None: not shown, or not said)")
    final_video_seconds: float | None = Field(
        None, ge=0, le=1e5, allow_inf_nan=False, description="seconds the final video played on screen")
    client_ts: float | None = _client_ts()

    @field_validator("rule")
    @classmethod
    def _rule(cls, v: str) -> str:
        v = _text(v, "rule") or ""
        if not v:
            raise ValueError("rule must say something: the participant's rule in their own words")
        return v

    @field_validator("comments")
    @classmethod
    def _comments(cls, v: str | None) -> str | None:
        return _text(v, "comments") or None


# -- the app ----------------------------------------------------------------------------------
def own_session(sid: str, request: Request) -> WebSession:
    """The session, for a request from the browser that started it. A dependency, so it is
    checked before the body is validated: a stranger learns nothing from a session's answers."""
    session = request.app.state.manager.get(sid)
    if session is None:
        raise ApiError(404, "unknown_session", f"unknown session {sid[:40]!r}")
    if not session.holds_key(key_cookies(request)):
        raise ApiError(403, "not_session_owner",
                       f"session {sid} takes answers only from the browser that started it: this request has "
                       f"no valid session key (the {KEY_COOKIE} cookie set when the session started); answer "
                       "from the page the session was started on")
    request.app.state.limits.touch(sid)  # only its own page keeps a session from going idle
    return session


Owned = Annotated[WebSession, Depends(own_session)]


def answerer(session: WebSession, request: Request) -> dict:
    return session.answered_by(request.client.host if request.client else None)


def page_signals(config: StudyConfig, conditions: dict[str, tuple[StudyConfig, EpisodeBuilder]] | None
                 ) -> dict[str, Signal]:
    """The signals a study asks for (its conditions', else its own), each with a web page."""
    names = [c.signal for c, _ in conditions.values()] if conditions else [config.signal]
    return {n: page_signal(n) for n in names}


def page_signal(name: str) -> Signal:
    """The signal ``name``, if people can give it (it has a web page and form); else ValueError."""
    signal = get_signal(name)
    if signal.page is None or signal.WebForm is None:
        raise ValueError(f"signal {name!r} has no web page (Signal.page and Signal.WebForm): people cannot give "
                         f"it; signals with a page: {', '.join(n for n in SIGNALS.names() if get_signal(n).page)}")
    for file in (signal.page, signal.how, *signal.page_assets):
        if file is not None and not signal.page_file(file).is_file():
            raise ValueError(f"signal {name!r}: its page file {signal.page_file(file)} does not exist")
    return signal


def answer_body():
    """The answer request's body: the web form of a signal with a page, chosen by its ``kind``
    (every such signal's, so a wrong kind is told which session asks for what)."""
    forms = tuple(f for f in (get_signal(n).WebForm for n in SIGNALS.names()) if f is not None)
    return forms[0] if len(forms) == 1 else Annotated[Union[forms], Field(discriminator="kind")]  # noqa: UP007


def _from_page(session: WebSession, form: WebForm):
    """The maker of h for the waiting question, from the page's form (by the session's signal)."""
    if form.kind != session.config.signal:
        raise AnswerRejected(
            f"this session asks for {session.config.signal} answers (kind '{session.config.signal}'), "
            f"not '{form.kind}'",
            status=422,
        )
    signal = get_signal(session.config.signal)

    def make(q: Question) -> SignalAnswer:
        return signal.from_web(form, session.shown_round(q))

    return make


def create_app(
    config: StudyConfig,
    builder: EpisodeBuilder | None = None,
    limits: Limits | None = None,
    clock: Callable[[], float] = time.monotonic,
    study: StudyFile | None = None,
    conditions: dict[str, tuple[StudyConfig, EpisodeBuilder]] | None = None,
) -> FastAPI:
    """The app for one study. ``builder`` builds each session's episode; by default
    :func:`activeintent.runner.build_episode` with the study's options. ``limits`` are the
    per-client, size and quota limits (see :mod:`activeintent.web.limits`); ``clock`` is what
    the idle timeout and rate limits count seconds with. ``study`` (a study file) and its
    ``conditions`` (name → StudyConfig and builder) replace the single ``config`` for the
    sessions; ``config`` still gives the folder and the server's limits."""
    limits = limits or Limits()
    signals = page_signals(config, conditions)
    manager = SessionManager(config, builder or runner_builder(config), conditions=conditions, study=study)
    guard = SessionLimits(manager, limits, clock=clock)

    @asynccontextmanager
    async def lifespan(app: FastAPI):
        # the render processes start now, not during the first participant's first wait
        if not await asyncio.to_thread(warm_render_pool, config.render_workers) and config.render_workers > 1:
            log.warning("the %d render processes could not start: every video is drawn in the server's "
                        "own process (longer waits between rounds)", config.render_workers)
        sweeper = asyncio.create_task(_sweep(guard))
        try:
            yield
        finally:
            sweeper.cancel()
            manager.shutdown()

    app = FastAPI(
        title="activeintent human-in-the-loop study",
        description="A person gives the sparse signal h (preference or stop) that a learner learns from.",
        version="1",
        docs_url=None,  # the Swagger page loads scripts from a CDN; the schema is at /openapi.json
        redoc_url=None,
        lifespan=lifespan,
    )
    app.state.manager = manager
    app.state.limits = guard
    install_error_handlers(app)
    app.add_middleware(BodyGuard, max_body_bytes=limits.max_body_bytes, drain_bytes=limits.drain_bytes,
                       drain_timeout=limits.body_timeout)
    # outermost: a request's connection learns when its head is complete (see web/transport.py)
    connections = ConnectionGuard(header_timeout=limits.header_timeout,
                                  max_connections_per_client=limits.max_connections_per_client,
                                  max_connections=limits.max_connections)
    app.state.connections = connections
    app.add_middleware(RequestPhases, guard=connections)

    app.add_api_route("/api/config", lambda: config_view(config, study, manager), methods=["GET"],
                      summary="The study's configuration (what every session runs)")
    add_session_routes(app, manager, guard)
    add_page_routes(app, signals)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    return app


def config_view(config: StudyConfig, study: StudyFile | None, manager: SessionManager) -> dict:
    """GET /api/config: what every session of the study runs (a study file's conditions are not
    for participants to read)."""
    if study is not None:
        # conditions differ per participant and are not for participants to read
        return {"study": True, "consent": study.consent, "require_pid": study.require_pid,
                "rounds": next(iter(manager.conditions.values()))[0].budget,
                "url_parameters": list(URL_PARAMETERS)}
    assigned = config.design == "assigned-rule"
    # never the method, the condition or the rule's name: a participant could read them in the
    # browser's tools (the rule's sentence, which an assigned-rule study shows anyway, is fine)
    return {
        "study": False,
        "consent": None,
        "require_pid": False,
        "url_parameters": list(URL_PARAMETERS),
        "rounds": config.budget,
        "design": config.design,
        "intention_description": config.intention_description if assigned else None,
        "show_estimate": config.show_estimate,
        "fps": config.fps,
        "video_size": list(config.video_size),
    }


# What a participant's browser may read of summary.json: never the method, the condition, the
# intention or the learner's estimate (the researcher reads summary.json and study-export).
PARTICIPANT_RESULT = ("budget", "signals_used", "rounds_used", "answers", "design")


def participant_result(summary: dict) -> dict:
    return {k: summary[k] for k in PARTICIPANT_RESULT if k in summary}


def add_session_routes(app: FastAPI, manager: SessionManager, guard: SessionLimits) -> None:
    """The session API: start, state, answer, video events, UI events, questionnaire, result, files."""

    def session_or_404(sid: str) -> WebSession:
        session = manager.get(sid)
        if session is None:
            raise ApiError(404, "unknown_session", f"unknown session {sid[:40]!r}")
        guard.touch(sid)  # somebody still cares about it: not idle
        return session

    @app.post("/api/sessions", status_code=201, summary="Start a session (its episode starts at once)")
    def create_session(request: Request, response: Response, body: NewSession | None = None) -> dict:
        body = body or NewSession()
        client = request.client.host if request.client else "unknown"
        key, key_sha256 = new_session_key()
        session = guard.create(client, participant=body.participant, seed=body.seed, pid=body.pid,
                               study_id=body.study_id, prolific_session_id=body.prolific_session_id,
                               consent=body.consent, key_sha256=key_sha256, start=body.start)
        response.set_cookie(KEY_COOKIE, key, max_age=KEY_COOKIE_MAX_AGE, path=f"/api/sessions/{session.id}",
                            httponly=True, samesite="strict", secure=request.url.scheme == "https")
        return session_state(session)

    @app.post("/api/sessions/{sid}/start", summary="Start an enrolled session's episode (the page's Start)")
    def start_session(session: Owned, request: Request) -> dict:
        client = request.client.host if request.client else "unknown"
        return session_state(guard.start(session, client))

    @app.post("/api/sessions/{sid}/leave", status_code=204, response_class=Response,
              summary="The session's page is closing (a beacon): cancelled unless a page of it comes back soon")
    async def leave_session(sid: str, request: Request) -> Response:
        # by hand, not the Owned dependency: a beacon's body is whatever the browser sends
        session = manager.get(sid)
        if session is None:
            raise ApiError(404, "unknown_session", f"unknown session {sid[:40]!r}")
        if not session.holds_key(key_cookies(request)):
            raise ApiError(403, "not_session_owner", f"session {sid} can be left only by the browser that started it")
        if session.active:
            guard.leave(sid)
        return Response(status_code=204)

    @app.get("/api/sessions/{sid}", summary="Session state: round i of K, the question, z, status")
    def get_session(sid: str) -> dict:
        return session_state(session_or_404(sid))

    def post_answer(session: Owned, request: Request, body: WebForm) -> dict:
        client = {name: getattr(body, name) for name in body.logged}
        h = session.answer(body.round, _from_page(session, body), client=client, by=answerer(session, request))
        return {"accepted": True, "round": body.round, "answer": h.model_dump(mode="json")}

    # the body's type is known only now (the signals registered when the app is made)
    post_answer.__annotations__["body"] = answer_body()
    app.post("/api/sessions/{sid}/answer", summary="Answer the waiting round (names the round)")(post_answer)

    @app.post("/api/sessions/{sid}/video", summary="The round's video: ready, ended or a replay starts")
    def post_video(session: Owned, body: VideoReport) -> dict:
        return {"round": body.round, "viewing": session.video_event(body.round, body.event, body.media_time)}

    @app.post("/api/sessions/{sid}/final-video", summary="The final attempt's video: ready, ended or a replay starts")
    def post_final_video(session: Owned, body: FinalVideoReport) -> dict:
        return {"viewing": session.final_video_event(body.event, body.media_time)}

    @app.post("/api/sessions/{sid}/events", summary="Append raw UI events (client timestamps kept)")
    def post_events(session: Owned, body: EventBatch) -> dict:
        events = [e.model_dump() for e in body.events]
        with guard.events_quota(session, event_lines_size(events)):
            n = session.log_events(events)
        return {"logged": n}

    @app.post("/api/sessions/{sid}/questionnaire", status_code=201,
              summary="The end-of-session questionnaire (once, after the final attempt)")
    def post_questionnaire(session: Owned, request: Request, body: QuestionnaireAnswers) -> dict:
        record = session.submit_questionnaire(body.model_dump(), by=answerer(session, request))
        # the participant's own answers back, not the session's condition or rule (kept on disk)
        own = ("final_attempt", "rule", "comments", "final_video_watched", "final_video_seconds", "submitted")
        return {"saved": True, "questionnaire": {k: record.get(k) for k in own}}

    @app.get("/api/sessions/{sid}/result", summary="How the episode ended, once finished (summary.json stays on disk)")
    def get_result(sid: str) -> dict:
        session = session_or_404(sid)
        if session.result is None:
            raise ApiError(409, "no_result_yet", f"session {sid} is {session.status}; no result yet")
        return participant_result(session.result)

    @app.get("/api/sessions/{sid}/files/{name}", summary="A video of this session", response_class=FileResponse)
    def get_file(sid: str, name: str):
        session = session_or_404(sid)
        path = None
        if len(name) <= MAX_FILE_NAME and SERVED_FILE.fullmatch(name):
            try:
                path = session.file(name)
            except OSError:  # whatever the file system thinks of the name: not one of ours
                path = None
        if path is None:
            raise ApiError(404, "file_not_found", f"no file {name[:80]!r} in session {sid} "
                           "(only its .webm/.mp4/.gif videos are served)")
        media = {".webm": "video/webm", ".mp4": "video/mp4"}.get(path.suffix, "image/gif")
        if path.suffix == ".mp4" and session.live_export(path.with_suffix(".webm").name) is not None:
            # an MP4 is whole only at the end (its index is written last): not sent half made
            raise ApiError(409, "video_not_ready", f"{name} is still being drawn; it is complete with its .webm")
        live = session.live_export(name)
        if live is not None:  # still being drawn: sent as it grows (activeintent.web.live)
            return StreamingResponse(follow(live), media_type=media, headers={"Cache-Control": "no-store"})
        return FileResponse(path, media_type=media, headers={"Cache-Control": "no-store"})


def add_page_routes(app: FastAPI, signals: dict[str, Signal]) -> None:
    """The start and done pages, and each signal's own page, instructions and scripts."""
    for route, page in PAGES.items():
        app.add_api_route(route, _page(STATIC / page), methods=["GET"], include_in_schema=False)
    for name, signal in signals.items():  # each signal's own page, instructions and scripts
        app.add_api_route(signal_page(name), _page(signal.page_file(signal.page)), methods=["GET"],
                          include_in_schema=False)
        if signal.how:
            app.add_api_route(f"{signal_page(name)}/how", _page(signal.page_file(signal.how)), methods=["GET"],
                              include_in_schema=False)
        for asset in signal.page_assets:
            app.add_api_route(f"{signal_page(name)}/{asset}", _file(signal.page_file(asset)), methods=["GET"],
                              include_in_schema=False)


async def _sweep(guard: SessionLimits) -> None:
    """Cancel idle sessions now and then, so an abandoned tab frees its slot without waiting
    for the next new session to ask."""
    every = max(1.0, min(30.0, guard.limits.idle_timeout / 4, guard.limits.reconnect_grace / 2))
    while True:
        await asyncio.sleep(every)
        try:
            await run_in_threadpool(guard.expire_idle)
            guard.forget_quiet_clients()
        except Exception:  # the sweeper must outlive any one bad sweep
            log.exception("idle sweep failed")


def _page(path: Path):
    def serve_page():
        return FileResponse(path, media_type="text/html", headers={"Cache-Control": "no-store"})

    return serve_page


def _file(path: Path):
    def serve_file():
        return FileResponse(path, headers={"Cache-Control": "no-store"})

    return serve_file


def runner_builder(config: StudyConfig) -> EpisodeBuilder:
    """Sessions built by :func:`activeintent.runner.build_episode` from the study's run spec. A
    free-rule study gives no intention: the runner's default stands in for the simulated parts
    and is neither shown nor scored (see :func:`activeintent.web.session.study_summary`)."""
    # People watch physics; the session exports its own videos; the learner is scored on the
    # test scenes after the last answer only (no one waits for a curve).
    run = config.run.with_options(video="none", curve=False)
    # The final attempt is what participants judge: with an assigned rule, on a table where
    # that rule can be shown at all; a free rule is unknown, so on the first table the learner's
    # own belief expects to be able to show its goals on.
    show = "first-feasible" if config.design == "assigned-rule" else "learner-showable"

    def build(seed: int, out_dir: Path, user, observers):
        return build_episode(run.with_options(seed=seed), out_dir, user=user, observers=observers, show_final=show)

    return build
