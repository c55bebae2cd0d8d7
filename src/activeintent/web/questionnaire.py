"""A session's end-of-session questionnaire: asked once the episode has ended, kept once in
``questionnaire.json`` (a second submission is refused and the first kept as it was)."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

from activeintent.web.basics import write_json
from activeintent.web.errors import ApiError


class Questionnaire:
    def __init__(self, folder: Path, session_id: str):
        self.path = folder / "questionnaire.json"
        self.session_id = session_id
        self.record: dict | None = None
        self._lock = threading.Lock()

    @property
    def submitted(self) -> bool:
        return self.record is not None

    def submit(self, answers: dict, *, status: str, active: bool, asks_final_attempt: bool, about: dict[str, Any],
               by: dict | None = None) -> dict:
        """Keep ``answers`` (after the episode, once): ``about`` says whose session it was,
        ``asks_final_attempt`` whether the page asked about the robot's final attempt."""
        sid = self.session_id
        if active:
            raise ApiError(409, "conflict", f"session {sid} is {status}: the questionnaire comes "
                           "after the robot's final attempt")
        if asks_final_attempt and answers.get("final_attempt") is None:
            raise ApiError(422, "invalid_answer", "final_attempt is required: did the final attempt do what "
                           "you wanted? 'yes', 'partly' or 'no'")
        if not asks_final_attempt and answers.get("final_attempt") is not None:
            raise ApiError(422, "invalid_answer", f"session {sid} ended without a final attempt "
                           f"({status}); leave final_attempt out")
        with self._lock:
            if self.record is not None or self.path.exists():
                raise ApiError(409, "already_submitted", f"the questionnaire of session {sid} is already "
                               "answered; the answers are kept as they were")
            record = {**about, "session_status": status, "submitted": time.time(), **answers, "answered_by": by}
            write_json(self.path, record)
            self.record = record
        return record
