"""The user's sparse signal h (the paper's feedback), shared by users and learners."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel

PreferenceChoice = Literal["A", "B", "cant_choose", "new_scene"]


class PreferenceFeedback(BaseModel):
    """h for the preference method: which of two trajectories τ^a, τ^b the user prefers.

    ``new_scene`` is the original UI's "New Env": this scene cannot show my preference.
    """

    kind: Literal["preference"] = "preference"
    choice: PreferenceChoice

    def describe(self) -> str:
        return {
            "A": "the user preferred goal A",
            "B": "the user preferred goal B",
            "cant_choose": "the user could not choose (both similar, or both bad)",
            "new_scene": "the user asked for a new scene: this one cannot show the preference",
        }[self.choice]


class StopFeedback(BaseModel):
    """h for the stop (clicker) methods: the time the user pressed stop, or None.

    ``stop_time`` is in seconds of trajectory time; None means the user watched to the end
    without objection. ``tick`` is the trajectory log index, ``step_index`` the skill being
    executed at the stop. ``new_scene`` is the clicker UI's "New Env".
    """

    kind: Literal["stop"] = "stop"
    stop_time: float | None = None
    tick: int | None = None
    frame: int | None = None
    step_index: int | None = None
    new_scene: bool = False

    @property
    def stopped(self) -> bool:
        return self.stop_time is not None

    def describe(self) -> str:
        if self.new_scene:
            return "the user asked for a new scene: this one cannot show the preference"
        if self.stop_time is None:
            return "the user watched to the end without stopping the robot"
        step = f" during step {self.step_index + 1}" if self.step_index is not None else ""
        return f"the user stopped the robot at t = {self.stop_time:.2f} s{step}"


Feedback = PreferenceFeedback | StopFeedback
