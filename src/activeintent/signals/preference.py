"""The ``preference`` signal: two trajectories τ^a, τ^b; h ∈ {A, B, can't choose}.

The one choice model, used by simulated users and by Bayesian learners with their own
parameters. With d = u(s_a) − u(s_b) and σ the similarity of the two outcomes::

    U_A = d/2,  U_B = −d/2,  U_C = m − |d|/2            (C = can't choose)
    P(o) = (1 − λ) · softmax_o(β·U_o + κ·σ·1[o = C]) + λ/3

m is the indifference margin, κ the confusion of near-identical outcomes, λ a lapse rate.
β = ∞ is the exact chooser: A if d > m, B if d < −m, else can't choose.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from activeintent.signals.base import Answer, Judge, ShownRound, Signal, WebForm
from activeintent.world.state import WorldState
from activeintent.world.trajectory import Trajectory

CHOICES: tuple[str, str, str] = ("A", "B", "cant_choose")
SIMILARITY_LENGTH = 0.05  # metres: a block 5 cm from its counterpart is e⁻¹ as similar
PREDICTIVE_BLOCK = 64  # queries per block of predictive_many (memory: 64 × H × 3 floats)


class PreferenceAnswer(Answer):
    signal: Literal["preference"] = "preference"
    choice: Literal["A", "B", "cant_choose"] | None = None

    def _describe(self) -> str:
        return {
            "A": "the user preferred goal A",
            "B": "the user preferred goal B",
            "cant_choose": "the user could not choose (both similar, or both bad)",
            None: "no answer",
        }[self.choice]

    def _kind(self) -> str:
        return str(self.choice)


class PreferenceForm(WebForm):
    """The preference page's answer: the choice, or a new scene."""

    kind: Literal["preference"]
    choice: Literal["A", "B", "cant_choose", "new_scene"]


class PreferenceModel(BaseModel):
    """Parameters of the choice model (a user's true ones, or a learner's assumption)."""

    model_config = ConfigDict(extra="forbid", ser_json_inf_nan="constants")

    beta: float = Field(12.0, ge=0, description="β: rationality on utility differences (inf = exact)")
    indifference: float = Field(0.05, ge=0, description="m: differences below this are not worth a choice")
    confusion: float = Field(1.0, ge=0, description="κ: log-odds added to can't choose for identical outcomes")
    lapse: float = Field(0.03, ge=0, lt=1, description="λ: probability of a uniformly random answer")


def similarity(a: WorldState, b: WorldState, length: float = SIMILARITY_LENGTH) -> float:
    """σ ∈ [0, 1]: mean over shared blocks of exp(−distance / length); 1 for identical outcomes."""
    common = [n for n in a.blocks if n in b.positions]
    if not common:
        return 0.0
    return float(np.mean([math.exp(-float(np.linalg.norm(a.pos(n) - b.pos(n))) / length) for n in common]))


def choice_probabilities(u_a: np.ndarray, u_b: np.ndarray, sim: float, m: PreferenceModel) -> np.ndarray:
    """[..., 3] P(A), P(B), P(can't choose) for utilities u_a, u_b (broadcast)."""
    d = np.asarray(u_a, float) - np.asarray(u_b, float)
    if math.isinf(m.beta):
        p = np.zeros(d.shape + (3,))
        tie = (np.abs(d) < m.indifference) | (np.abs(d) <= 1e-9)
        p[..., 0] = ~tie & (d > 0)
        p[..., 1] = ~tie & (d < 0)
        p[..., 2] = tie
    else:
        s = np.clip(np.asarray(sim, float), 0.0, 1.0)  # a number, or one per row of d ([n, 1])
        logits = np.stack([m.beta * d / 2, -m.beta * d / 2, m.beta * (m.indifference - np.abs(d) / 2) + m.confusion * s], -1)
        logits -= logits.max(axis=-1, keepdims=True)
        p = np.exp(logits)
        p /= p.sum(axis=-1, keepdims=True)
    return (1 - m.lapse) * p + m.lapse / 3


class PreferenceSignal(Signal):
    name = "preference"
    shows = 2
    Answer = PreferenceAnswer
    Model = PreferenceModel
    page_folder = "pages"
    page = "preference.html"
    how = "preference-how.html"
    page_assets = ("preference.js",)
    WebForm = PreferenceForm
    buttons = ("A", "B", "cant_choose", "new_scene")

    def from_web(self, form: PreferenceForm, shown: ShownRound) -> PreferenceAnswer:
        return self.new_scene() if form.choice == "new_scene" else PreferenceAnswer(choice=form.choice)

    def _probs(self, shown: list[Trajectory], judge: Judge, model: PreferenceModel) -> np.ndarray:
        if len(shown) != 2:
            raise ValueError(f"a preference query shows two trajectories τ^a, τ^b; got {len(shown)}")
        a, b = shown[0].outcome, shown[1].outcome
        return choice_probabilities(judge.utility(a), judge.utility(b), similarity(a, b), model)

    def learner_model(self) -> PreferenceModel:
        # People choose noisily (Boltzmann β of a few units on a [0, 1] utility scale): a learner
        # assuming near-perfect choosers over-trusts single answers.
        return PreferenceModel(beta=5.0, lapse=0.05)

    def predictive(self, shown, judge, model) -> np.ndarray:
        return self._probs(shown, judge, model)

    def predictive_many(self, queries, judge, model):
        """The same values as :meth:`predictive` per query, computed in blocks of queries:
        each outcome's utilities once, the choice model on [queries, n] at a time."""
        utilities: dict[int, np.ndarray] = {}

        def u(traj: Trajectory) -> np.ndarray:
            if id(traj) not in utilities:
                utilities[id(traj)] = np.asarray(judge.utility(traj.outcome), float)
            return utilities[id(traj)]

        for start in range(0, len(queries), PREDICTIVE_BLOCK):
            block = queries[start:start + PREDICTIVE_BLOCK]
            for shown in block:
                if len(shown) != 2:
                    raise ValueError(f"a preference query shows two trajectories τ^a, τ^b; got {len(shown)}")
            sims = np.array([[similarity(a.outcome, b.outcome)] for a, b in block])
            yield from choice_probabilities(np.stack([u(a) for a, _ in block]), np.stack([u(b) for _, b in block]),
                                            sims, model)

    def likelihood(self, answer, shown, judge, model) -> np.ndarray:
        if answer.choice is None:
            raise ValueError("a preference answer without a choice can only be a new-scene request")
        return self._probs(shown, judge, model)[:, CHOICES.index(answer.choice)]

    def sample(self, shown, judge, model, rng) -> PreferenceAnswer:
        p = self._probs(shown, judge, model)[0]
        # One uniform draw per answer (also for the exact user) keeps random streams aligned.
        k = int(np.searchsorted(np.cumsum(p), rng.random() * p.sum(), side="right"))
        return PreferenceAnswer(choice=CHOICES[min(k, 2)])  # type: ignore[arg-type]
