"""A new signal as a plug-in: the person rates one trajectory from 1 to 5 stars.

Nothing in the package is edited: this file registers the signal, and the method
``bayes-rating`` (the Bayesian learner for it) exists at once. Run it with:

    bin/activeintent bench --plugin examples/my_signal.py --methods bayes-rating,zero-signal \\
        --suite paper --trials 2 --env symbolic --llm none --out runs/rating

People give it too: its page is ``my_signal.html`` beside this file (what the browser shows and
posts), and ``from_web`` reads what the page posts. Serve a study with it:

    bin/activeintent serve --plugin examples/my_signal.py --method bayes-rating --intention color-match

Observation model: the rating centres on 1 + 4·u(s), u ∈ [0, 1] the outcome's utility under
the intention z, with Gaussian noise of ``noise`` stars, mixed with a lapse λ.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from activeintent.signals import SIGNALS, Answer, AnswerRejected, ShownRound, Signal, WebForm

STARS = np.arange(1, 6)


class RatingAnswer(Answer):
    signal: Literal["rating"] = "rating"
    stars: int | None = Field(None, ge=1, le=5)

    def _describe(self) -> str:
        return f"the user rated the robot's work {self.stars} of 5 stars"


class RatingForm(WebForm):
    """What my_signal.html posts: the stars, or a new scene."""

    kind: Literal["rating"]
    stars: int | None = Field(None, ge=1, le=5)
    new_scene: bool = False


class RatingModel(BaseModel):
    model_config = ConfigDict(extra="forbid")

    noise: float = Field(0.7, gt=0, description="sd of the rating around 1 + 4·u, in stars")
    lapse: float = Field(0.05, ge=0, lt=1, description="λ: probability of a uniformly random rating")


class RatingSignal(Signal):
    name = "rating"
    shows = 1
    Answer = RatingAnswer
    Model = RatingModel
    page = "my_signal.html"
    WebForm = RatingForm

    def from_web(self, form: RatingForm, shown: ShownRound) -> RatingAnswer:
        if form.new_scene:
            return self.new_scene()
        if form.stars is None:
            raise AnswerRejected("a rating needs 'stars' (1 to 5), or 'new_scene': true", status=422)
        return RatingAnswer(stars=form.stars)

    def predictive(self, shown, judge, model: RatingModel) -> np.ndarray:
        (traj,) = shown
        centre = 1 + 4 * judge.utility(traj.outcome)  # [n]
        logits = -0.5 * ((STARS[None, :] - centre[:, None]) / model.noise) ** 2
        p = np.exp(logits - logits.max(axis=1, keepdims=True))
        p /= p.sum(axis=1, keepdims=True)
        return (1 - model.lapse) * p + model.lapse / len(STARS)

    def likelihood(self, answer: RatingAnswer, shown, judge, model) -> np.ndarray:
        return self.predictive(shown, judge, model)[:, answer.stars - 1]

    def sample(self, shown, judge, model, rng) -> RatingAnswer:
        p = self.predictive(shown, judge, model)[0]
        return RatingAnswer(stars=int(rng.choice(STARS, p=p)))


SIGNALS.register("rating", RatingSignal, help="1–5 stars for one trajectory (example plug-in)")
