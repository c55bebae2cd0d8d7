"""The unit of a benchmark: one (method, intention, trial) item, the bench's options, and the
function that runs one item in a worker (a pool process or a Ray task)."""

from __future__ import annotations

import json
import traceback
from pathlib import Path

from pydantic import BaseModel, Field

from activeintent.bench.legacy import BENCH_FORMAT, bench_json
from activeintent.protocol import trial_seeds
from activeintent.runner import build_episode, for_method
from activeintent.spec import RunSpec


class WorkItem(BaseModel):
    method: str
    intention: str  # name, or path.py:NAME for a user-defined intention
    trial: int

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.method, self.intention, self.trial)

    @property
    def slug(self) -> str:
        name = self.intention.replace("/", "_").replace(":", "_").replace(".py", "")
        return f"{self.method}/{name}/trial{self.trial}"


class BenchConfig(BaseModel):
    """A benchmark: ``run`` (the spec every episode shares; each item sets its method, intention
    and seeds) × methods × intentions × trials, and how they are executed (jobs, backend)."""

    methods: list[str]
    intentions: list[str] = Field(default_factory=list)
    intention_files: list[str] = Field(default_factory=list)
    trials: int = Field(20, ge=1)
    seed: int = Field(0, ge=0)
    jobs: int = Field(1, ge=1)
    backend: str = Field("local", pattern="^(local|ray)$")  # not a setting: a bench may resume on another
    ray_address: str | None = None  # with backend ray: an existing cluster (else RAY_ADDRESS, else a local Ray)
    retry_errors: bool = False
    keep_episodes: bool = False  # per-episode folders (rounds.jsonl, summary.json)
    run: RunSpec = Field(default_factory=lambda: RunSpec.from_options(video="none"))

    def items(self) -> list[WorkItem]:
        names = list(self.intentions) + list(self.intention_files)
        return [WorkItem(method=m, intention=i, trial=t) for t in range(self.trials) for i in names for m in self.methods]


def read_bench_config(path: Path) -> BenchConfig:
    """The options a results folder was made with (its bench.json, of any format)."""
    return BenchConfig.model_validate(bench_json(path))


def write_bench_config(options: BenchConfig, path: Path) -> None:
    path.write_text(json.dumps({"format": BENCH_FORMAT, **json.loads(options.model_dump_json())}, indent=2))


def run_item(item: WorkItem, options: RunSpec, bench_seed: int, out: str, keep: bool) -> dict:
    """One episode in a worker process (own simulator client, own model handles)."""
    user_defined = ".py:" in item.intention
    seed, test_seed = trial_seeds(bench_seed, item.intention, item.trial)
    run = for_method(options, item.method).with_options(
        intention=None if user_defined else item.intention, intention_file=item.intention if user_defined else None,
        seed=seed, test_seed=test_seed)
    base = {"method": item.method, "intention": item.intention, "trial": item.trial}
    try:
        episode = build_episode(run, Path(out) / "episodes" / item.slug if keep else None)
        try:
            result = episode.run()
        finally:
            episode.env.close()
        record = result.model_dump(mode="json")
        record.pop("tests", None)  # per-scene detail stays in the episode folder
        return {**record, **base}
    except Exception as err:  # noqa: BLE001 - recorded, never crashes the benchmark
        return {**base, "success": None, "error": f"{type(err).__name__}: {err}",
                "traceback": traceback.format_exc(limit=8)}
