"""Wiring one episode from options: models, learner, executor, simulator, user.

`activeintent run`, `activeintent bench` and the web app all build episodes here, so a run
means the same thing everywhere.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from pydantic import BaseModel, Field

from activeintent.episode import Episode, EpisodeConfig, EpisodeSeeds, RoundLog

DEFAULT_METHOD = "bayes-stop"  # beats the paper's methods in the benchmark (README, Results)
DEFAULT_INTENTION = "color-match"


class UserOptions(BaseModel):
    """Simulated-user parameters (recorded in every result)."""

    beta: float = Field(float("inf"), description="rationality β of the preference user; inf = exact")
    reaction_delay_mean: float = 0.5
    reaction_delay_sd: float = 0.15
    false_stop: float = 0.0
    missed_stop: float = 0.0


class RunOptions(BaseModel):
    method: str = DEFAULT_METHOD
    intention: str | None = None
    intention_file: str | None = None
    rounds: int = 5
    seed: int = 0
    test_scenes: int = 1
    llm: str = "embedded"
    vlm: str | None = None
    base_url: str | None = None
    cache: str | None = None
    cache_mode: str = "record"
    executor: str = "plan"
    retriever: str = "symbolic"
    epsilon: float = 2.0
    design_scenes: bool = True
    save_videos: bool = True
    track_progress: bool = False
    user: UserOptions = Field(default_factory=UserOptions)


class Models:
    """The models a run uses, loaded on first use (Bayesian methods may need none)."""

    def __init__(self, options: RunOptions):
        self.options = options
        self._llm = None
        self._vlm = None

    def _load(self, spec: str):
        from activeintent.llm.registry import load_model

        if spec == "none":
            return None
        o = self.options
        return load_model(spec, base_url=o.base_url, cache_path=o.cache, cache_mode=o.cache_mode)

    @property
    def llm(self):
        if self._llm is None and self.options.llm != "none":
            self._llm = self._load(self.options.llm)
        return self._llm

    @property
    def vlm(self):
        if self.options.vlm is None:
            return None
        if self._vlm is None:
            self._vlm = self._load(self.options.vlm)
        return self._vlm

    def usage(self) -> tuple[int, int, int]:
        calls = prompt = completion = 0
        for m in {id(m): m for m in (self._llm, self._vlm) if m is not None}.values():
            if m.usage is None:
                continue
            totals = m.usage.snapshot()
            calls += totals.calls
            prompt += totals.prompt_tokens
            completion += totals.completion_tokens
        return calls, prompt, completion


def build_episode(
    options: RunOptions,
    out_dir: str | Path | None,
    user=None,
    on_round: Callable[[RoundLog], None] | None = None,
    env=None,
) -> Episode:
    """Everything `activeintent run` does before the loop starts. Errors in the options
    (unknown method, intention, executor, model spec) are raised here, before any work."""
    from activeintent.act.base import make_executor
    from activeintent.intentions.registry import resolve_intention
    from activeintent.learners.registry import SIGNAL, check_method, make_learner
    from activeintent.sim.env import TabletopEnv
    from activeintent.users.simulated import UserConfig, make_user

    check_method(options.method)
    intention = resolve_intention(options.intention or (None if options.intention_file else DEFAULT_INTENTION),
                                  options.intention_file)
    models = Models(options)
    seeds = EpisodeSeeds.from_seed(options.seed)
    # Bayesian methods need no model; given one, it proposes open-ended hypotheses.
    llm = models.llm
    learner = make_learner(options.method, llm=llm, vlm=models.vlm, retriever=options.retriever,
                           seed=seeds.learner, design_scenes=options.design_scenes,
                           epsilon=options.epsilon)
    executor = make_executor(options.executor, model=llm)
    if user is None:
        u = options.user
        user = make_user(SIGNAL[options.method], intention,
                         UserConfig(beta=u.beta, reaction_delay_mean=u.reaction_delay_mean,
                                    reaction_delay_sd=u.reaction_delay_sd, false_stop=u.false_stop,
                                    missed_stop=u.missed_stop), seed=seeds.user)
    config = EpisodeConfig(rounds=options.rounds, seed=options.seed, test_scenes=options.test_scenes,
                           save_videos=options.save_videos, track_progress=options.track_progress)
    return Episode(learner, intention, user, executor, env or TabletopEnv(), config, out_dir,
                   usage=models.usage, on_round=on_round,
                   extra_config={"options": options.model_dump(mode="json")})
