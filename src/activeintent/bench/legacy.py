"""Records and ``bench.json`` files of older shapes, read as this code writes them (copies; a
committed folder is never rewritten for a shape change).

Shapes this reads:

- results lines whose ``config.options`` held the spec in flat option names, with the settings
  every line repeated at its top (env, user preset, prior, models, executor, retriever, variant);
  now ``config.spec`` holds the spec as it ran, with the method's own settings only;
- ``bench.json`` formats 1 and 2 (``run`` in flat option names) and 3 (``run`` in sections, the
  learner's section flat).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from activeintent.learners.registry import get_method
from activeintent.registry import UnknownName
from activeintent.spec import RunSpec

# bench.json's format. 4: ``run`` is a RunSpec whose learner section is {method, settings}. 3: the
# learner's section flat. 2: ``run`` in flat option names. 1 (no "format"): options added since
# take the values they had in effect then (:func:`_format_1_values`).
BENCH_FORMAT = 4

# Settings added after results were recorded, with the value those results ran with.
ADDED_SETTINGS = {"scenes": "sampled", "language": 1}

# What older lines repeated at their top from the spec (``config`` holds it): dropped on read.
# ``retriever`` and ``variant`` were the spec's there and are the learner's own now (None for a
# method without them), so a line read from the old shape has neither.
REPEATED_SETTINGS = ("user_preset", "prior", "llm", "vlm", "executor", "retriever", "variant")


def _format_1_values(run: dict) -> dict:
    """Values of options that did not exist when a format-1 folder was made: the paper's methods
    ran what is now ``--variant structured``, ε was also eq. 3's threshold, and no test pool was
    scored at k = K."""
    return {"variant": "structured", "early_threshold": run.get("epsilon", 2.0), "test_pool": 0}


def _flat_run(run: dict) -> dict[str, Any]:
    """A format-3 ``run`` (sections, the learner's flat) in option names."""
    learner = dict(run.get("learner") or {})
    flat = {**run.get("protocol", {}), **run.get("models", {}), **learner,
            "env": (run.get("env") or {}).get("name", "pybullet"), "plugin": run.get("plugins", [])}
    user = run.get("user") or {}
    flat.update({"user": user.get("preset", "human"), "intention": user.get("intention"),
                 "intention_file": user.get("intention_file")})
    return flat


def _spec_of_flat(flat: dict[str, Any]) -> RunSpec:
    flat = {**ADDED_SETTINGS, **flat}
    if "plugins" in flat:
        flat["plugin"] = flat.pop("plugins")
    return RunSpec.from_options(**flat)


def bench_json(path: Path) -> dict:
    """A folder's bench.json as the current format's fields; ValueError for a format newer than
    this code."""
    data = json.loads(Path(path).read_text())
    version = data.pop("format", 1)
    if not isinstance(version, int) or version > BENCH_FORMAT:
        raise ValueError(f"{path} is bench.json format {version!r}; this code reads formats 1 to {BENCH_FORMAT}: "
                         "update activeintent")
    run = data.get("run")
    if isinstance(run, dict) and version < 4:
        flat = _flat_run(run) if version == 3 else {**(_format_1_values(run) if version == 1 else {}), **run}
        data["run"] = _spec_of_flat(flat).model_dump(mode="json")
    return data


def migrated(record: dict) -> dict:
    """A results line (or an episode's summary) as this code writes it."""
    record = dict(record)
    fmt = record.get("format")
    if isinstance(fmt, int) and fmt < 3 and record.get("test_pool") is None:
        record["test_pool"] = 0  # format 2 scored no test pool
    config = record.get("config")
    if not isinstance(config, dict) or "options" not in config:
        return record
    for key in REPEATED_SETTINGS:
        record.pop(key, None)
    spec = _spec_of_flat(dict(config["options"]))
    try:
        own = get_method(spec.learner.method).own(spec.learner.settings)
    except UnknownName:  # a plug-in's method, its file not loaded: its settings as recorded
        own = spec.learner.settings
    spec = spec.model_copy(update={"learner": spec.learner.model_copy(update={"settings": own})})
    config = {k: v for k, v in config.items() if k != "options"}
    record["config"] = {**config, "spec": spec.model_dump(mode="json", exclude={"plugins"})}
    return record
