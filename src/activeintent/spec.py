"""The run specification: one :class:`RunSpec` says what one episode is, in five sections.

    protocol  what is measured and how (K, seeds, test scenes, the "new scene" rule, video)
    models    which LLM / MLLM answer and how their replies are cached
    learner   the method and its settings (prior, ε, eq. 3's threshold, variant, y → plan)
    env       where plans run
    user      who answers (the simulated user's preset) and the hidden intention

`activeintent run`, `bench`, `serve` and the Python API all build one, validate it once and pass
it whole to :func:`activeintent.runner.build_episode`. The command line speaks in flat option
names (``--budget``, ``--llm``); :data:`OPTIONS` maps each to its section, and
:meth:`RunSpec.from_options` / :meth:`RunSpec.options` convert (records and bench.json of earlier
formats were written flat).

The seed is split once, here (:attr:`ProtocolConfig.seeds`), into the episode's named streams.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from activeintent.goals.language import LATEST, check_language
from activeintent.protocol import (
    DEFAULT_BUDGET,
    DEFAULT_TEST_POOL,
    DEFAULT_TEST_SCENES,
    NewSceneRule,
)

DEFAULT_METHOD = "bayes-stop"
DEFAULT_INTENTION = "color-match"
VARIANTS = ("faithful", "structured")


@dataclass(frozen=True)
class EpisodeSeeds:
    """Every random choice flows from one seed; the test scenes from the trial's test seed.
    Every stream is read: the query scenes, their block layouts, the simulated user's noise, the
    learner's own draws, the test scenes."""

    scenes: int
    layouts: int
    user: int
    learner: int
    test: int

    @classmethod
    def from_seed(cls, seed: int, test_seed: int | None = None) -> EpisodeSeeds:
        kids = [int(k.generate_state(1)[0]) for k in np.random.SeedSequence(seed).spawn(5)]
        if test_seed is not None:
            kids[4] = int(np.random.SeedSequence(test_seed).generate_state(1)[0])
        return cls(*kids)


class ProtocolConfig(BaseModel):
    """What is measured and how: the same for every method compared."""

    model_config = ConfigDict(extra="forbid")

    budget: int = Field(DEFAULT_BUDGET, ge=0, le=100, description="K: signals the user gives")
    seed: int = Field(0, ge=0, description="seed of the episode's query scenes, user noise and learner")
    test_seed: int | None = Field(None, ge=0, description="seed of the test scenes (default: from seed)")
    test_scenes: int = Field(DEFAULT_TEST_SCENES, ge=1, le=200, description="test scenes scored after every signal")
    test_pool: int = Field(DEFAULT_TEST_POOL, ge=0, le=1000, description="more test scenes, scored at k = K only")
    new_scene: NewSceneRule = "counted"
    stop_when_done: bool = Field(False, description="end early when a learner allowed to finish says done (not in benchmarks)")
    curve: bool = Field(True, description="score after every signal (False: only at k = K)")
    max_goal_retries: int = Field(1, ge=0, description="re-asks when y cannot be turned into motion")
    video: str = Field("none", pattern="^(none|final|all)$", description="GIFs written: none, the final test, or all")
    video_fps: int = 10

    @cached_property
    def seeds(self) -> EpisodeSeeds:
        """The one split of ``seed`` (and ``test_seed``) into the episode's named streams."""
        return EpisodeSeeds.from_seed(self.seed, self.test_seed)


class ModelsConfig(BaseModel):
    """Which models answer (specs as in docs/models.md) and how their replies are cached."""

    model_config = ConfigDict(extra="forbid")

    llm: str = "embedded"
    vlm: str | None = None
    base_url: str | None = None
    cache: str | None = None
    cache_mode: str = Field("record", pattern="^(record|replay|off)$")


class LearnerConfig(BaseModel):
    """The method and the settings the methods read (each method reads the ones it has)."""

    model_config = ConfigDict(extra="forbid")

    method: str = DEFAULT_METHOD
    prior: str | None = Field(None, pattern="^(length|uniform|fitted|file:.+)$",
                              description="length | uniform | fitted (lang-* only) | file:PATH (lang-*, from `prior fit`) | "
                              "None: the method's own (lang-*: fitted, the others: length)")
    scenes: str = Field("sampled", description="bayes-* and lang-*: how query scenes are chosen, a name of "
                        "SCENE_DESIGNS (sampled | belief | a plug-in's)")
    language: int = Field(LATEST, description="lang-*: the goal language's version (recorded, so that an episode "
                          "run before the language grew replays in its own)")
    epsilon: float = Field(2.0, ge=0, description="ε: seconds before the stop for image I_b")
    early_threshold: float | None = Field(2.0, ge=0, description="eq. 3: a stop earlier than this shows no I_b (None: ε)")
    variant: str = Field("faithful", description="the paper's methods: faithful (as the paper ran them) | structured")
    design_scenes: bool = True
    retriever: str = Field("symbolic", pattern="^(symbolic|vision)$")
    executor: str = "plan"

    @field_validator("variant")
    @classmethod
    def _known_variant(cls, v: str) -> str:
        if v not in VARIANTS:
            raise ValueError(f"Unknown variant {v!r}; valid variants: {', '.join(VARIANTS)}.")
        return v

    @field_validator("language")
    @classmethod
    def _known_language(cls, v: int) -> int:
        return check_language(v)


class EnvConfig(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = "pybullet"


class UserConfig(BaseModel):
    """Who answers: a simulated user's preset, with the hidden intention it holds."""

    model_config = ConfigDict(extra="forbid")

    preset: str = "human"
    intention: str | None = None
    intention_file: str | None = Field(None, description="path.py:NAME")


class RunSpec(BaseModel):
    """One episode, whole: see the module's docstring."""

    model_config = ConfigDict(extra="forbid")

    protocol: ProtocolConfig = Field(default_factory=lambda: ProtocolConfig(video="final"))
    models: ModelsConfig = Field(default_factory=ModelsConfig)
    learner: LearnerConfig = Field(default_factory=LearnerConfig)
    env: EnvConfig = Field(default_factory=EnvConfig)
    user: UserConfig = Field(default_factory=UserConfig)
    plugins: list[str] = Field(default_factory=list, description="Python files that register plug-ins")

    @classmethod
    def from_options(cls, base: RunSpec | None = None, **values: Any) -> RunSpec:
        """A spec from flat option names (the CLI's, and earlier formats'), over ``base`` (default:
        the defaults). A bad value raises ValueError naming the option as the CLI spells it."""
        unknown = sorted(set(values) - set(OPTIONS))
        if unknown:
            raise ValueError(f"unknown option(s) {', '.join(unknown)}; valid options: {', '.join(OPTIONS)}")
        data = (base or cls()).model_dump()
        for name, value in values.items():
            section, field = OPTIONS[name]
            if section is None:
                data[field] = value
            else:
                data[section][field] = value
        try:
            return cls.model_validate(data)
        except ValidationError as err:
            where = {v: k for k, v in OPTIONS.items()}
            msgs = []
            for e in err.errors():
                loc = e["loc"]
                key = (loc[0], loc[1]) if len(loc) > 1 and loc[0] != "plugins" else (None, loc[0])
                name = where.get(key, ".".join(map(str, loc)))  # type: ignore[arg-type]
                msgs.append(f"--{str(name).replace('_', '-')}: {e['msg']} (got {e.get('input')!r})")
            raise ValueError("; ".join(msgs)) from None

    def options(self) -> dict[str, Any]:
        """The spec in flat option names (what records and bench.json keep as ``options``/``run``)."""
        data = self.model_dump(mode="json")
        return {name: (data[field] if section is None else data[section][field])
                for name, (section, field) in OPTIONS.items()}

    def with_options(self, **values: Any) -> RunSpec:
        """A copy with some flat options changed (validated)."""
        return RunSpec.from_options(base=self, **values)

    @property
    def seeds(self) -> EpisodeSeeds:
        return self.protocol.seeds


# Flat option name (CLI, records) → (section, field). The order is the records' order.
OPTIONS: dict[str, tuple[str | None, str]] = {
    "method": ("learner", "method"),
    "intention": ("user", "intention"),
    "intention_file": ("user", "intention_file"),
    "plugins": (None, "plugins"),
    "budget": ("protocol", "budget"),
    "seed": ("protocol", "seed"),
    "test_seed": ("protocol", "test_seed"),
    "test_scenes": ("protocol", "test_scenes"),
    "test_pool": ("protocol", "test_pool"),
    "env": ("env", "name"),
    "user": ("user", "preset"),
    "new_scene": ("protocol", "new_scene"),
    "prior": ("learner", "prior"),
    "scenes": ("learner", "scenes"),
    "language": ("learner", "language"),
    "llm": ("models", "llm"),
    "vlm": ("models", "vlm"),
    "base_url": ("models", "base_url"),
    "cache": ("models", "cache"),
    "cache_mode": ("models", "cache_mode"),
    "executor": ("learner", "executor"),
    "retriever": ("learner", "retriever"),
    "epsilon": ("learner", "epsilon"),
    "early_threshold": ("learner", "early_threshold"),
    "variant": ("learner", "variant"),
    "design_scenes": ("learner", "design_scenes"),
    "video": ("protocol", "video"),
    "curve": ("protocol", "curve"),
    "stop_when_done": ("protocol", "stop_when_done"),
}

# Options added after results were recorded, with the value those results ran with: a record or a
# bench.json without the option gets it (bench.work.bench_json, bench.verify.migrated).
OPTIONS_ADDED = {"scenes": "sampled", "language": 1}
