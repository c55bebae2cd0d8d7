"""The on-disk formats, owned here only: ``summary.json`` and ``rounds.jsonl`` of an episode,
``results.jsonl`` of a benchmark (its lines are written by :func:`dumps`; reading, checking and
appending them is results.py's). Every record carries ``format`` (FORMAT_VERSION) so an old
folder is never read as a new one.
"""

from __future__ import annotations

import json
import unicodedata
from pathlib import Path

from activeintent.protocol import FORMAT_VERSION


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
