"""``lang-<signal>``: the Bayesian active learner over the goal language.

The same learner as ``bayes-<signal>`` (belief, EIG over candidate plans, final answer) with
the language's hypothesis space, a judge that scores every goal on a state in one numpy pass,
and a space that grows while it learns (proposals.py): after every answer the neighbours of
the likely goals, and with ``--llm`` the model's goals in the language, join the belief with
their prior 2^-L(z) and their likelihood on every answer so far.
"""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from activeintent.goals.facts import Facts, facts
from activeintent.goals.goal import Goal
from activeintent.goals.nodes import LATEST, check_language, speaking
from activeintent.goals.prior import goal_bits, load_prior
from activeintent.learners.base import LearnerContext, Method, RoundRecord
from activeintent.learners.bayes.judge import HypothesisJudge, trajectory_steps, utility
from activeintent.learners.bayes.learner import BayesConfig, BayesLearner, BayesSettings
from activeintent.learners.lang.hypotheses import LangHypothesis, LangSpace, lang_space
from activeintent.learners.lang.proposals import neighbours, propose_goals
from activeintent.llm.base import ModelError
from activeintent.world import WorldState
from activeintent.world.trajectory import Trajectory

KEEP = 3000  # goals kept after de-duplication (the shortest ones)


class LangJudge(HypothesisJudge):
    """Judges outcomes under every goal of one or more LangSpaces at once (vectors concatenated
    in the order of the spaces)."""

    def __init__(self, spaces: LangSpace | list[LangSpace]):
        self.spaces = [spaces] if isinstance(spaces, LangSpace) else list(spaces)
        super().__init__(tuple(h for sp in self.spaces for h in sp.hypotheses))

    def _cat(self, get) -> np.ndarray:
        parts = [get(sp) for sp in self.spaces]
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    def judge(self, f: Facts) -> tuple[np.ndarray, np.ndarray]:
        if len(self.spaces) == 1:
            return self.spaces[0].compiled.eval(f)
        got = [sp.compiled.eval(f) for sp in self.spaces]
        return np.concatenate([g[0] for g in got]), np.concatenate([g[1] for g in got])

    def feasible(self, objects) -> np.ndarray:
        return self._cat(lambda sp: sp.feasible(tuple(objects)))

    def prefetch(self, states) -> None:  # the compiled judge needs no batching
        return None

    def utility(self, state: WorldState) -> np.ndarray:
        holds, score = self.judge(facts(state))
        return utility(score, holds)

    def step_away(self, fb: Facts, fa: Facts, block: str, ok: bool = True) -> np.ndarray:
        """Per z: does moving ``block`` (facts before → after) move away from z? Its score
        drops, or (a step that ran) the block left a place z allows."""
        _, sb = self.judge(fb)
        _, sa = self.judge(fa)
        away = sa < sb - 1e-9
        if ok:
            away = away | self._cat(lambda sp: sp.compiled.moved_off(fb, fa, block))
        return away

    def first_away(self, traj: Trajectory) -> np.ndarray:
        return self._away.get_or_make(traj, lambda: self._first_away(traj))

    def _first_away(self, traj: Trajectory) -> np.ndarray:
        out = np.full(self.size, -1)
        for k, (fb, fa, block, ok) in enumerate(trajectory_steps(traj)):
            if fb is fa:
                continue
            out[(out < 0) & self.step_away(fb, fa, block, ok)] = k
            if (out >= 0).all():
                break
        return out


class LangPriorSettings(BaseModel):
    """What a person chooses for any learner over the goal language: its prior and version."""

    model_config = ConfigDict(extra="forbid")

    prior: str = Field("fitted", pattern="^(length|uniform|fitted|file:.+)$",
                       description="P(z): fitted (to what people ask, data/requests; goals/prior.py) | length "
                       "(description length) | file:PATH (written by `prior fit`) | uniform (the ablation)")
    language: int = Field(LATEST, description="The goal language's version (recorded, so that an episode run before "
                          "the language grew replays in its own)")

    @field_validator("language")
    @classmethod
    def _known_language(cls, version: int) -> int:
        return check_language(version)

    @model_validator(mode="after")
    def _prior_loads(self) -> LangPriorSettings:
        load_prior(self.prior, self.language)  # a missing, malformed or other-language file is refused before any work
        return self


class LangSettings(LangPriorSettings, BayesSettings):
    """... and, for those that ask, how their scenes are chosen."""


class LangConfig(LangSettings, BayesConfig):
    """The Bayesian learner's settings plus how the space grows (none tuned to intentions)."""

    rejuvenate_top: int = Field(8, ge=0, description="after each answer, neighbours of this many likely goals join")
    join_partners: int = Field(32, ge=0, description="... and each of them joined with each of this many likely goals")
    max_added: int = Field(20000, ge=0, description="goals added in one episode at most")
    proposals_per_call: int = Field(3, ge=1, le=5, description="goals asked of the model per call")


class LangLearner(BayesLearner):
    """BayesLearner over the goal language, with a space that grows around its belief."""

    def __init__(self, signal, rng=None, llm=None, config: LangConfig | None = None,
                 hypotheses: tuple[LangHypothesis, ...] | None = None, keep: int = KEEP):
        config = config or LangConfig()
        hyps = tuple(hypotheses or lang_space(0, keep, config.prior, config.language).hypotheses)
        super().__init__(signal, rng, None, config, hyps)
        self.config: LangConfig = config
        self.llm = llm
        self.name = f"lang-{self.signal}"
        spaces = list(dict.fromkeys(h.space for h in hyps))
        if tuple(h for sp in spaces for h in sp.hypotheses) != hyps:
            raise ValueError("lang learner: hypotheses must be whole LangSpaces, in order")
        for sp in spaces:
            sp.reset()  # the shared space keeps no planner verdicts from an earlier episode
        self.base = spaces
        self.prior = spaces[0].prior if spaces else None  # the goals' prior (None: length)
        self.language = spaces[0].language if spaces else config.language  # what it enumerates and charges
        self.added = LangSpace([], prior=self.prior, language=self.language)  # goals that joined during this episode
        self.judge = LangJudge(self.base)
        self.keys = {h.name for h in hyps}
        self.cut = max(h.bits for h in hyps) + 1e-9  # the starting space holds every distinct goal up to here
        self.growth = {"neighbours": 0, "model_answers": 0, "model_fit": 0, "model_new": 0}
        self.model_goals: set[str] = set()

    # ---- growing the space ----

    def _admit(self, goals) -> list[str]:
        """Add goals not held yet (up to the episode's cap), scored on every answer so far."""
        room = self.config.max_added - len(self.added.goals)
        # A goal as short as the starting space's longest is in it or behaves like one of it
        # (de-duplication kept the shortest): adding it would count that behaviour twice.
        fresh = [g for g in goals if g.key not in self.keys and self.bits(g) > self.cut][:max(room, 0)]
        if not fresh:
            return []
        n_old = len(self.added.goals)
        self.added = LangSpace(list(self.added.goals) + fresh, prior=self.prior, language=self.language)
        new_space = LangSpace(fresh, prior=self.prior, language=self.language)  # scored alone, then merged: the judge below is temporary
        log_lik = self._log_lik(LangJudge(new_space))
        self.judge = LangJudge(self.base + [self.added])
        self.belief.extend(self.added.hypotheses[n_old:], log_lik)
        self.belief.hyps = self.judge.hyps  # the same goals, bound to the merged space
        self.keys.update(g.key for g in fresh)
        return [g.key for g in fresh]

    def bits(self, goal: Goal) -> float:
        """L(z) under the learner's prior."""
        with speaking(self.language):
            return goal_bits(goal, self.prior)

    def _rejuvenate(self) -> int:
        if not self.config.rejuvenate_top:
            return 0
        likely = [h.goal for h, _ in self.top(self.config.join_partners)]  # type: ignore[attr-defined]
        with speaking(self.language):
            near = neighbours(likely[:self.config.rejuvenate_top], likely)
        added = self._admit(near)
        self.growth["neighbours"] += len(added)
        return len(added)

    def _propose(self) -> list[str]:
        """Goals in the language from the model (``--llm``), decoded under the language's schema."""
        self.proposal_calls += 1
        history = "\n".join(
            f"{i}. scene: {', '.join(o.scene.objects)}; shown: {'; '.join(o.texts)}; answer: {o.answer.describe()}"
            for i, o in enumerate(self.observations, 1))
        likely = [(h.goal, w) for h, w in self.top(5)]  # type: ignore[attr-defined]
        try:
            # the request's seed is not drawn from the learner's generator: asking the model must
            # not change which queries follow, so runs with and without --llm stay paired
            with speaking(self.language):
                goals, answered = propose_goals(self.llm, likely, history, self.config.proposals_per_call,  # type: ignore[arg-type]
                                                seed=len(self.observations))
        except ModelError as err:
            self.proposal_errors.append(str(err)[:300])
            return []
        self.growth["model_answers"] += answered
        self.growth["model_fit"] += len(goals)
        self.model_goals.update(g.key for g in goals)
        added = self._admit(goals)
        self.growth["model_new"] += len(added)
        return added

    def observe(self, record: RoundRecord, trajectories: list[Trajectory]) -> str | None:
        out = super().observe(record, trajectories)  # Bayes' rule, then model proposals (if any)
        if record.answer is not None:
            n = self._rejuvenate()
            if self.log:
                self.log[-1]["neighbours_added"] = n
        return out

    def mass_of(self, key: str) -> float:
        """w of the goal with this key (0 when the belief does not hold it)."""
        hit = [i for i, h in enumerate(self.hyps) if h.name == key]
        return float(self.weights[hit].sum()) if hit else 0.0

    def stats(self) -> dict:
        out = super().stats()
        w = self.weights
        model = np.array([h.name in self.model_goals for h in self.hyps])
        start = sum(len(sp.goals) for sp in self.base)
        out.update(self.growth)
        out.update({
            "space_start": start,
            "added_mass": round(float(w[start:].sum()), 4),
            "model_goal_mass": round(float(w[model].sum()), 4) if model.any() else 0.0,
            "top_is_model_goal": bool(self.top()[0][0].name in self.model_goals),
        })
        return out


def lang_method(signal: str) -> Method:
    """The registry entry of ``lang-<signal>``."""

    def build(ctx: LearnerContext) -> LangLearner:
        return LangLearner(signal, rng=ctx.learner_seed, llm=ctx.llm, config=LangConfig(**ctx.settings.model_dump()))

    return Method(signal, False, build, f"ours: growing belief over the goal language, {signal} queries by EIG",
                  goal_language=True, colour={"stop": "#2ca02c", "preference": "#98df8a"}.get(signal),
                  settings=LangSettings)


def lang_zero_signal() -> Method:
    """``lang-zero-signal``: the goal language's prior best guess, no questions (the baseline of
    lang-* under the same prior)."""

    def build(ctx: LearnerContext) -> LangLearner:
        learner = LangLearner("stop", rng=ctx.learner_seed, config=LangConfig(**ctx.settings.model_dump()))
        learner.asks = False
        learner.name = "lang-zero-signal"
        return learner

    return Method("stop", False, build, "baseline: the goal language's prior best guess, asks nothing",
                  "baseline", goal_language=True, settings=LangPriorSettings)
