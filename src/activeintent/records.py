"""The on-disk formats, owned here only: ``summary.json`` and ``rounds.jsonl`` of an episode,
``results.jsonl`` of a benchmark (its lines are written by :func:`dumps`; reading, checking and
appending them is results.py's). Every record carries ``format`` (FORMAT_VERSION) so an old
folder is never read as a new one.
"""

from __future__ import annotations

import json
import unicodedata
from pathlib import Path

from pydantic import BaseModel, Field

from activeintent.protocol import FORMAT_VERSION


class RoundLog(BaseModel):
    round: int
    scene: list[str]
    scene_source: str
    layout_seed: int
    z: str
    goals: list[str]
    labels: list[str]  # "A", "B" for two trajectories, "y" for one
    plans: list[str]
    failures: list[str | None]
    executed: list[bool]  # did anything move in each τ?
    answer: dict
    counted: bool  # did this answer use the budget?
    signals_used: int  # counted answers so far, this one included
    retrieved: str | None
    retriever: str | None
    variant: str | None = None  # the paper methods' variant (faithful | structured)
    done: bool
    why: dict = Field(default_factory=dict)
    calls: list[dict] = Field(default_factory=list)
    timing: dict[str, float] = Field(default_factory=dict)


class TestLog(BaseModel):
    scene: list[str]
    layout_seed: int
    z: str
    goal: str
    plan: str
    failure: str | None
    feasible: bool  # can the hidden intention be satisfied here? (decided after the answer)
    success: bool  # symbolic outcome
    success_physics: bool | None = None  # at k = K in the pybullet env


class EpisodeResult(BaseModel):
    format: int = FORMAT_VERSION
    method: str
    intention: str
    seed: int
    test_seed: int
    env: str
    budget: int
    new_scene: str
    success: float | None  # success@K: share of the feasible scenes of the whole test pool satisfied
    success_at: list[float | None]  # k < K: on the first test_scenes scenes; k = K: the whole pool
    success_physics: float | None = None
    physics_disagreements: int | None = None
    test_scenes: int  # scored at every k
    test_pool: int = 0  # scored at k = K besides them
    test_excluded: int  # of the scenes scored at k = K: infeasible for the hidden intention, not scored
    test_scored: int | None = None  # of the scenes scored at k = K: feasible, so scored
    signals_used: int
    answers: dict[str, int] = Field(default_factory=dict)
    rounds_used: int
    done_at: int | None = None  # first signal count at which the learner said "done"
    final_z: str = ""  # the learner's final z and goal on test scene final_scene: the first that
    final_goal: str = ""  # can show the hidden intention (scene 0 when none can)
    final_scene: int | None = None
    retriever: str | None = None
    variant: str | None = None
    llm_calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    wall_s: float = 0.0
    time_split: dict[str, float] = Field(default_factory=dict)
    tests: list[TestLog] = Field(default_factory=list)
    learner_stats: dict = Field(default_factory=dict)
    diagnostics: dict = Field(default_factory=dict)  # the learner's, per answer (bits, kinds, top z)
    user: dict = Field(default_factory=dict)
    error: str | None = None
    config: dict = Field(default_factory=dict)
    provenance: dict = Field(default_factory=dict)  # provenance.py: code, versions, CPU, date


def _clean(obj):
    """Values safe for strict JSON: finite numbers (others → None), valid Unicode strings."""
    if isinstance(obj, float):
        return obj if obj == obj and obj not in (float("inf"), float("-inf")) else None
    if isinstance(obj, str):
        text = obj.encode("utf-8", "replace").decode("utf-8")
        return "".join(c for c in text if c in "\n\t" or unicodedata.category(c) != "Cc")
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    return obj


def dumps(record: dict) -> str:
    return json.dumps(_clean(record), allow_nan=False)


class EpisodeRecorder:
    """An episode observer that writes ``rounds.jsonl`` (one line per answered round) and
    ``summary.json`` into ``out``."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.out.mkdir(parents=True, exist_ok=True)
        (self.out / "rounds.jsonl").write_text("")

    def answered(self, log) -> None:
        with (self.out / "rounds.jsonl").open("a") as f:
            f.write(dumps({"format": FORMAT_VERSION, **log.model_dump(mode="json")}) + "\n")

    def finished(self, result) -> None:
        (self.out / "summary.json").write_text(json.dumps(_clean(result.model_dump(mode="json")), indent=2))


def read_rounds(path: str | Path) -> list[dict]:
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]
