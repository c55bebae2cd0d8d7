"""The unit of a benchmark: one (method, intention, trial) item, the bench's options, and the
function that runs one item in a worker (a pool process or a Ray task)."""

from __future__ import annotations

import traceback
from pathlib import Path

from pydantic import BaseModel, Field

from activeintent.protocol import trial_seeds
from activeintent.runner import RunOptions


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


class BenchOptions(BaseModel):
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
    run: RunOptions = Field(default_factory=lambda: RunOptions(video="none"))

    def items(self) -> list[WorkItem]:
        names = list(self.intentions) + list(self.intention_files)
        return [WorkItem(method=m, intention=i, trial=t) for t in range(self.trials) for i in names for m in self.methods]


def protocol_fields(run: RunOptions) -> dict:
    """What every results line records about how it was measured."""
    return {"env": run.env, "user_preset": run.user, "budget": run.budget, "new_scene": run.new_scene,
            "prior": run.prior, "test_scenes": run.test_scenes, "test_pool": run.test_pool, "llm": run.llm, "executor": run.executor,
            "vlm": run.vlm, "retriever": run.retriever, "variant": run.variant}


def run_item(item: WorkItem, options: RunOptions, bench_seed: int, out: str, keep: bool) -> dict:
    """One episode in a worker process (own simulator client, own model handles)."""
    user_defined = ".py:" in item.intention
    seed, test_seed = trial_seeds(bench_seed, item.intention, item.trial)
    run = options.model_copy(update={
        "method": item.method,
        "intention": None if user_defined else item.intention,
        "intention_file": item.intention if user_defined else None,
        "seed": seed, "test_seed": test_seed,
    })
    base = {"method": item.method, "intention": item.intention, "trial": item.trial, **protocol_fields(run)}
    try:
        from activeintent.runner import build_episode

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
