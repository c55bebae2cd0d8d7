"""What a participant's page reads of a session (GET /api/sessions/{id}): the question on
screen, progress as "round i of K", the guess z where the study shows it, the final attempt and
the questionnaire's state. A view only: nothing here changes the session."""

from __future__ import annotations

from typing import TYPE_CHECKING

from activeintent.web.session import Guess, scene_legend, signal_page

if TYPE_CHECKING:
    from activeintent.web.session import WebSession


def visible_guess(session: WebSession) -> Guess | None:
    """The guess the participant may see now: the current question's (while it waits for an
    answer) or the final one (once finished); None when the study hides it."""
    status = session.status
    guess = session.guess if status == "waiting-for-answer" else session.final_guess if status == "finished" else None
    return guess if session.guess_visible(guess) else None


def session_state(session: WebSession) -> dict:
    config = session.config
    q = session.user.question
    status = session.status
    question = None
    if q is not None and status == "waiting-for-answer":
        objects = list(q.scene.objects)
        question = {
            "round": q.round,
            "kind": config.signal,
            "scene": objects,
            "legend": scene_legend(objects),
            # complete: the whole file is written (before that it is sent as it grows)
            "videos": [{**v.model_dump(), "complete": session.live_export(v.file) is None} for v in (q.presented or [])],
            "viewing": session.viewing(q.round),
        }
    guess = visible_guess(session)
    finished = status == "finished"
    submitted = session.questionnaire.submitted
    return {
        "id": session.id,
        # never the method, the condition or the rule's name (a participant could read them in
        # the browser's tools); the page's path is the signal's, which the page shows anyway
        "page": signal_page(config.signal),
        "design": config.design,
        "intention_description": config.intention_description,
        "show_estimate": config.show_estimate,
        "status": status,
        "phase": session.phase,
        "rounds": config.budget,
        "rounds_answered": len(session.rounds),
        "signals_used": session.signals_used,
        # the round the participant is on, as "round i of K"
        "progress": min(session.signals_used + 1, config.budget),
        "question": question,
        "button_order": session.enrolment.button_order,
        "estimate": guess.model_dump() if guess else None,
        # the completion code and redirect: once the questionnaire is in
        "completion": session.completion.model_dump() if session.completion and submitted else None,
        "final_video": session.final_video.model_dump() if session.final_video and finished else None,
        "final_legend": scene_legend(session.final_scene) if session.final_scene and finished else None,
        "success": session.result.get("success") if session.result else None,
        "success_basis": session.result.get("success_basis") if session.result else None,
        "questionnaire": {
            "open": not session.active and not submitted,
            "submitted": submitted,
            "asks_final_attempt": session.asks_final_attempt,
        },
        "error": session.error,
    }
