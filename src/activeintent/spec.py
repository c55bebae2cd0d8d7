"""The run specification: one :class:`RunSpec` says what one episode is, in six sections.

    protocol  what is measured and how (K, seeds, test scenes, the "new scene" rule, video)
    models    which LLM / MLLM answer and how their replies are cached
    learner   the method and its settings (its own config class says which: prior, ε, variant…)
    act       how y becomes motion (the executor)
    env       where plans run
    user      who answers (the simulated user's preset) and the hidden intention

`activeintent run`, `bench`, `serve` and the Python API all build one, validate it once and pass
it whole to :func:`activeintent.runner.build_episode`; records keep it as it ran. The command
line speaks in option names (``--budget``, ``--llm``): a field's own name unless it says another
(:func:`option_fields`); every other option is a learner setting.

The seed is split once, here (:attr:`ProtocolConfig.seeds`), into the episode's named streams.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from pydantic.fields import FieldInfo

from activeintent.llm.models import ModelsConfig
from activeintent.protocol import (
    DEFAULT_BUDGET,
    DEFAULT_TEST_POOL,
    DEFAULT_TEST_SCENES,
    NewSceneRule,
)

DEFAULT_METHOD = "bayes-stop"
DEFAULT_INTENTION = "color-match"


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

    budget: int = Field(DEFAULT_BUDGET, ge=0, le=100, description="K: signals the user gives; every answer counts")
    seed: int = Field(0, ge=0, description="Seed of every random choice")
    test_seed: int | None = Field(None, ge=0, description="Seed of the test scenes (default: from --seed); a bench "
                                  "record's config.spec.protocol.test_seed replays its episode")
    test_scenes: int = Field(DEFAULT_TEST_SCENES, ge=1, le=200, description="Test scenes scored after every signal")
    test_pool: int = Field(DEFAULT_TEST_POOL, ge=0, le=1000, description="More test scenes, scored after the last "
                           "signal (k = K)")
    new_scene: NewSceneRule = Field("counted", description="counted (every answer is a signal) | free (old rule, ≤3 "
                                    "uncounted) | off")
    stop_when_done: bool = Field(False, description="End early when a learner allowed to finish says done (not in "
                                 "benchmarks)")
    curve: bool = Field(True, description="Score after every signal (off: only at k = K; for slow models)")
    max_goal_retries: int = Field(1, ge=0, description="Re-asks when y cannot be turned into motion")
    video: str = Field("none", pattern="^(none|final|all)$", description="GIFs written: none | final | all")
    video_fps: int = Field(10, ge=1, description="Frames per second of the GIFs")

    @cached_property
    def seeds(self) -> EpisodeSeeds:
        """The one split of ``seed`` (and ``test_seed``) into the episode's named streams."""
        return EpisodeSeeds.from_seed(self.seed, self.test_seed)


class LearnerSpec(BaseModel):
    """The method and its settings. The settings are the method's own: its config class
    (``Method.settings``) validates them when the spec is checked (runner.check_spec) and a
    checked spec holds all of them, defaults included, as the episode ran."""

    model_config = ConfigDict(extra="forbid")

    method: str = Field(DEFAULT_METHOD, description="Learner (see `activeintent methods`)")
    settings: dict[str, Any] = Field(default_factory=dict)


class ActConfig(BaseModel):
    """How y becomes motion."""

    model_config = ConfigDict(extra="forbid")

    executor: str = Field("plan", description="y → plan: parse | plan | cap")


class EnvConfig(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field("pybullet", description="Where plans run: pybullet | symbolic",
                      json_schema_extra={"option": "env"})


class UserConfig(BaseModel):
    """Who answers: a simulated user's preset, with the hidden intention it holds."""

    model_config = ConfigDict(extra="forbid")

    preset: str = Field("human", description="Simulated-user preset: human | paper | exact (see docs/protocol.md)",
                        json_schema_extra={"option": "user"})
    intention: str | None = Field(None, description="Hidden intention (see `activeintent intentions`)")
    intention_file: str | None = Field(None, description="Your own intention: path.py:NAME")


SECTIONS = ("protocol", "models", "learner", "act", "env", "user")


class RunSpec(BaseModel):
    """One episode, whole: see the module's docstring."""

    model_config = ConfigDict(extra="forbid")

    protocol: ProtocolConfig = Field(default_factory=lambda: ProtocolConfig(video="final"))
    models: ModelsConfig = Field(default_factory=ModelsConfig)
    learner: LearnerSpec = Field(default_factory=LearnerSpec)
    act: ActConfig = Field(default_factory=ActConfig)
    env: EnvConfig = Field(default_factory=EnvConfig)
    user: UserConfig = Field(default_factory=UserConfig)
    plugins: list[str] = Field(default_factory=list, description="Python file registering signals, methods, envs… "
                               "(repeatable)", json_schema_extra={"option": "plugin"})

    @classmethod
    def from_options(cls, base: RunSpec | None = None, **values: Any) -> RunSpec:
        """A spec from option names (the CLI's: :func:`option_fields`), over ``base`` (default: the
        defaults). A name that is no section's field is a learner setting (None: not given, the
        method's own); the method's config class judges it when the spec is checked. A bad value
        raises ValueError naming the option as the CLI spells it."""
        routes = option_fields()
        data = (base or cls()).model_dump()
        for name, value in values.items():
            if name in routes:
                section, field, _ = routes[name]
                if section is None:
                    data[field] = value
                else:
                    data[section][field] = value
            elif value is None:
                data["learner"]["settings"].pop(name, None)
            else:
                data["learner"]["settings"][name] = value
        try:
            return cls.model_validate(data)
        except ValidationError as err:
            where = {(section, field): name for name, (section, field, _) in routes.items()}
            msgs = []
            for e in err.errors():
                loc = e["loc"]
                key = (loc[0], loc[1]) if len(loc) > 1 and loc[0] != "plugins" else (None, loc[0])
                name = where.get(key, ".".join(map(str, loc)))  # type: ignore[arg-type]
                msgs.append(f"--{str(name).replace('_', '-')}: {e['msg']} (got {e.get('input')!r})")
            raise ValueError("; ".join(msgs)) from None

    def options(self) -> dict[str, Any]:
        """The spec in option names: the sections' fields, then the learner's settings (for
        display: records keep the spec itself)."""
        data = self.model_dump(mode="json")
        out = {name: (data[field] if section is None else data[section][field])
               for name, (section, field, _) in option_fields().items()}
        return {**out, **data["learner"]["settings"]}

    def with_options(self, **values: Any) -> RunSpec:
        """A copy with some options changed (validated)."""
        return RunSpec.from_options(base=self, **values)

    @property
    def seeds(self) -> EpisodeSeeds:
        return self.protocol.seeds


def option_name(field: str, info: FieldInfo) -> str:
    """The command line's name of a field: its own, unless it says another (``env``: the env's name)."""
    extra = info.json_schema_extra
    return str(extra.get("option", field)) if isinstance(extra, dict) else field


def option_fields() -> dict[str, tuple[str | None, str, FieldInfo]]:
    """Every section field by its option name → (section, field, its pydantic FieldInfo); the
    learner's settings are not here (each method's config class has its own)."""
    out: dict[str, tuple[str | None, str, FieldInfo]] = {}
    for section in SECTIONS:
        model = RunSpec.model_fields[section].annotation
        for field, info in model.model_fields.items():  # type: ignore[union-attr]
            if (section, field) != ("learner", "settings"):
                out[option_name(field, info)] = (section, field, info)
    out[option_name("plugins", RunSpec.model_fields["plugins"])] = (None, "plugins", RunSpec.model_fields["plugins"])
    return out
