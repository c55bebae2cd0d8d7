"""Simulated users with a hidden intention: they give the sparse signal h for τ.

Two kinds, one per signal:

- :class:`PreferenceUser` watches τ^a and τ^b and answers A, B or cant_choose (the paper's
  "goal 1 better" / "goal 2 better" / "both bad or similar"), following the choice model of
  :mod:`activeintent.users.preference_model`.
- :class:`StopUser` watches one τ and presses stop shortly after the robot starts a skill that
  moves away from the intention (or never, when nothing goes wrong).

Both ask for a new scene (the UI's "New Env") when the scene cannot show the intention. All
randomness comes from the numpy Generator they are given; every parameter is in
:class:`UserConfig`, which the episode logs.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from activeintent.intentions.base import Intention
from activeintent.signals import PreferenceFeedback, StopFeedback
from activeintent.sim.trajectory import StepRecord, Trajectory
from activeintent.users.preference_model import (
    outcome_similarity,
    outcome_utility,
    preference_probabilities,
    sample_choice,
)
from activeintent.world import Scene, WorldState

SIGNALS: tuple[str, ...] = ("preference", "stop")
EXPORT_FPS = 10  # videos are exported at 10 frames per second: frame = floor(t · fps)


class UserConfig(BaseModel):
    """Every parameter of a simulated user (logged with each result)."""

    model_config = ConfigDict(extra="forbid", ser_json_inf_nan="constants")

    beta: float = Field(math.inf, ge=0, description="rationality β of the preference user; inf = exact")
    indifference: float = Field(0.05, ge=0, description="m: utility differences below this are not worth a choice")
    confusion: float = Field(1.0, ge=0, description="κ: extra log-odds of cant_choose for identical outcomes")
    reaction_delay_mean: float = Field(0.5, ge=0, description="seconds from a bad move becoming evident to the stop")
    reaction_delay_sd: float = Field(0.15, ge=0, description="sd of the reaction delay (normal, truncated at 0)")
    false_stop: float = Field(0.0, ge=0, le=1, description="probability of a stop at a random time for no reason")
    missed_stop: float = Field(0.0, ge=0, le=1, description="probability of not reacting to a bad move")
    new_scene_when_infeasible: bool = Field(True, description="ask for a new scene when it cannot show the intention")
    fps: int = Field(EXPORT_FPS, ge=1, description="video frame rate used for StopFeedback.frame")


def final_state(traj: Trajectory) -> WorldState:
    """The outcome of τ: the logged final state, else the last tick, else the initial state."""
    if traj.final_state is not None:
        return traj.final_state
    if traj.n_ticks > 0:
        return traj.state_at(traj.duration)
    if traj.initial_state is not None:
        return traj.initial_state
    raise ValueError("the trajectory has no states to judge (no ticks, no initial or final state)")


def _state_key(state: WorldState) -> tuple:
    return tuple(sorted(state.positions.items()))


class PreferenceUser:
    """Prefers the trajectory whose outcome better realises the hidden intention.

    See :mod:`activeintent.users.preference_model` for the exact choice probabilities:
    P(o) ∝ exp(β·U_o + κ·σ·1[o = C]) with U_A = d/2, U_B = −d/2, U_C = m − |d|/2,
    d = u(s_a) − u(s_b), u(s) = (score(s) + 1[satisfied(s)]) / 2 and σ the similarity of the two
    final states. β = ∞ is exact: the better one, or cant_choose when |d| < m (or a tie).
    """

    signal = "preference"

    def __init__(
        self,
        intention: Intention,
        beta: float = math.inf,
        similarity_confusion: float = 1.0,
        rng: np.random.Generator | None = None,
        indifference: float = 0.05,
        new_scene_when_infeasible: bool = True,
    ):
        self.intention = intention
        self.config = UserConfig(
            beta=beta,
            confusion=similarity_confusion,
            indifference=indifference,
            new_scene_when_infeasible=new_scene_when_infeasible,
        )
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self._memo: tuple[tuple, dict[str, float]] | None = None

    @classmethod
    def from_config(cls, intention: Intention, config: UserConfig, rng: np.random.Generator) -> PreferenceUser:
        user = cls(intention, rng=rng)
        user.config = config
        return user

    def probabilities(self, state_a: WorldState, state_b: WorldState) -> dict[str, float]:
        """P(h) over A, B, cant_choose for two outcomes."""
        key = (_state_key(state_a), _state_key(state_b), self.config.model_dump_json())
        if self._memo is not None and self._memo[0] == key:  # the same pair asked again
            return dict(self._memo[1])
        c = self.config
        probs = preference_probabilities(
            outcome_utility(self.intention, state_a),
            outcome_utility(self.intention, state_b),
            outcome_similarity(state_a, state_b),
            beta=c.beta,
            indifference=c.indifference,
            confusion=c.confusion,
        )
        self._memo = (key, probs)
        return dict(probs)

    def choose(self, state_a: WorldState, state_b: WorldState) -> PreferenceFeedback:
        """h for two outcomes (final states)."""
        probs = self.probabilities(state_a, state_b)
        if math.isinf(self.config.beta):
            choice = max(probs, key=lambda k: probs[k])
        else:
            choice = sample_choice(probs, self.rng)
        return PreferenceFeedback(choice=choice)  # type: ignore[arg-type]

    def respond(self, scene: Scene, trajectories: list[Trajectory]) -> PreferenceFeedback:
        """h for τ^a, τ^b shown in ``scene``."""
        if len(trajectories) != 2:
            raise ValueError(
                f"a preference user compares exactly two trajectories (τ^a, τ^b); got {len(trajectories)}"
            )
        if self.config.new_scene_when_infeasible and not self.intention.feasible(scene):
            return PreferenceFeedback(choice="new_scene")
        return self.choose(final_state(trajectories[0]), final_state(trajectories[1]))


class StopUser:
    """Presses stop shortly after the robot starts a skill that moves away from the intention.

    Watching τ step by step, the user finds the first executed skill whose outcome moves away
    (``intention.step_moves_away(state_before, state_after, skill)``). A failed skill (not ok)
    counts only if it visibly made things worse (the score dropped, e.g. it knocked a tower
    over): the robot trying and failing is not a move away from the intention. Each offending
    skill is missed independently with probability ``missed_stop`` (the user then reacts to
    the next one, if any). The stop comes at the skill's reveal time (when its destination
    becomes evident) plus a reaction delay ~ Normal(mean, sd) truncated at 0; it is clipped to
    the end of τ. With probability ``false_stop`` the user also presses stop at a uniformly
    random time although nothing is wrong; the earlier press counts. No press → stop_time None.
    """

    signal = "stop"

    def __init__(
        self,
        intention: Intention,
        reaction_delay: tuple[float, float] = (0.5, 0.15),
        false_stop: float = 0.0,
        missed_stop: float = 0.0,
        rng: np.random.Generator | None = None,
        new_scene_when_infeasible: bool = True,
        fps: int = EXPORT_FPS,
    ):
        self.intention = intention
        self.config = UserConfig(
            reaction_delay_mean=reaction_delay[0],
            reaction_delay_sd=reaction_delay[1],
            false_stop=false_stop,
            missed_stop=missed_stop,
            new_scene_when_infeasible=new_scene_when_infeasible,
            fps=fps,
        )
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self._verdicts: dict[tuple, bool] = {}

    @classmethod
    def from_config(cls, intention: Intention, config: UserConfig, rng: np.random.Generator) -> StopUser:
        user = cls(intention, rng=rng)
        user.config = config
        return user

    def moves_away(self, step: StepRecord) -> bool:
        before, after = step.state_before, step.state_after
        key = (_state_key(before), _state_key(after), step.skill.model_dump_json(), step.ok)
        if key not in self._verdicts:  # judging needs relations; the same τ is often re-judged
            if len(self._verdicts) > 512:
                self._verdicts.clear()
            if not step.ok:
                verdict = self.intention.score(after) < self.intention.score(before) - 1e-9
            else:
                verdict = self.intention.step_moves_away(before, after, step.skill)
            self._verdicts[key] = bool(verdict)
        return self._verdicts[key]

    def reaction_delay(self) -> float:
        mean, sd = self.config.reaction_delay_mean, self.config.reaction_delay_sd
        if sd == 0:
            return max(mean, 0.0)
        for _ in range(1000):  # rejection sampling of the truncated normal
            delay = float(self.rng.normal(mean, sd))
            if delay >= 0:
                return delay
        return 0.0

    def watch(self, traj: Trajectory) -> StopFeedback:
        """h for one trajectory."""
        c = self.config
        end = traj.duration
        stops: list[float] = []
        for step in traj.steps:
            if not self.moves_away(step):
                continue
            if c.missed_stop > 0 and self.rng.random() < c.missed_stop:
                continue
            stops.append(traj.time_of(step.reveal_tick) + self.reaction_delay())
            break
        if c.false_stop > 0 and self.rng.random() < c.false_stop:
            stops.append(float(self.rng.uniform(0.0, end)))
        if not stops:
            return StopFeedback(stop_time=None)
        t = float(min(max(min(stops), 0.0), end))
        return StopFeedback(
            stop_time=t,
            tick=traj.tick_at(t),
            frame=int(math.floor(t * c.fps + 1e-9)),
            step_index=traj.step_at(t),
        )

    def respond(self, scene: Scene, trajectories: list[Trajectory]) -> StopFeedback:
        """h for the one τ shown in ``scene``."""
        if len(trajectories) != 1:
            raise ValueError(f"a stop user watches exactly one trajectory; got {len(trajectories)}")
        if self.config.new_scene_when_infeasible and not self.intention.feasible(scene):
            return StopFeedback(new_scene=True)
        return self.watch(trajectories[0])


def make_user(
    signal: Literal["preference", "stop"] | str,
    intention: Intention,
    config: UserConfig | None = None,
    seed: int | np.random.Generator = 0,
) -> PreferenceUser | StopUser:
    """A simulated user for ``signal`` holding ``intention``; all its randomness from ``seed``."""
    config = config or UserConfig()
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    if signal == "preference":
        return PreferenceUser.from_config(intention, config, rng)
    if signal == "stop":
        return StopUser.from_config(intention, config, rng)
    raise ValueError(f"Unknown signal {signal!r}; valid signals: {', '.join(SIGNALS)}.")
