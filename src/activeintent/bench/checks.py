"""A results line is trusted only if it belongs to its folder: checked against the folder's
``bench.json`` (the plan) and against itself, cheaply (no episode is run).

- *Planned*: its method, intention and trial are among the bench's (trial < trials).
- *As planned*: the spec the line records (``config.spec``: protocol, models, the method's
  settings, executor, env, user preset) equals the one the folder gives its method, and its seeds are the ones its trial gets (``trial_seeds``; the test seed as the
  episode records it, its test-scene stream).
- *Consistent*: its format is one this code reads (older shapes are read by bench/legacy.py, never
  rewritten), its success equals the last value of its own success@k curve and the curve has
  K + 1 points, and its provenance has the shape ``provenance.py`` writes (a 40-hex commit
  that this checkout knows, when it is a full git checkout; a past date).

Each check returns (kind, reason) for results.py's ``load_results``.
"""

from __future__ import annotations

import datetime as dt
import re
import subprocess
from pathlib import Path

from activeintent.bench.legacy import migrated
from activeintent.bench.work import BenchConfig
from activeintent.memo import memoized
from activeintent.protocol import FORMAT_VERSION, trial_seeds
from activeintent.registry import load_plugin
from activeintent.runner import check_spec, for_method
from activeintent.spec import EpisodeSeeds

_HEX40 = re.compile(r"[0-9a-f]{40}")
_MISSING = object()
_FUTURE_SLACK = dt.timedelta(days=1)  # clocks of the machines that made a folder may be off


# What each episode of a folder has of its own (checked against its trial apart).
PER_EPISODE = frozenset({"protocol.seed", "protocol.test_seed", "user.intention", "user.intention_file",
                         "learner.method"})


# A result's own copies of its spec's fields: they must agree with it.
SPEC_COPIES = {"env": "env.name", "budget": "protocol.budget", "new_scene": "protocol.new_scene",
               "test_scenes": "protocol.test_scenes", "test_pool": "protocol.test_pool"}


def _flat(data: dict, prefix: str = "") -> dict[str, object]:
    out: dict[str, object] = {}
    for key, value in data.items():
        if isinstance(value, dict) and value:
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


class Plan:
    """What a folder's ``bench.json`` says its lines may be."""

    def __init__(self, options: BenchConfig):
        self.methods = set(options.methods)
        self.intentions = set(options.intentions) | set(options.intention_files)
        self.trials = options.trials
        self.seed = options.seed
        self.budget = options.run.protocol.budget
        self.run = options.run
        self._specs: dict[str, dict | None] = {}
        for path in options.run.plugins:  # its methods' settings say how its lines read (bench/legacy.py)
            try:
                load_plugin(path)
            except (OSError, ValueError):
                pass  # lines of its methods are then checked without their settings

    def spec(self, method: str) -> dict[str, object] | None:
        """The spec a line of ``method`` records, flat ('learner.settings.prior': …) and without
        what each episode has of its own (seeds, intention); None when it cannot be known here (a
        plug-in's method whose file is not at hand)."""
        if method not in self._specs:
            try:
                spec = check_spec(for_method(self.run, method)).model_dump(mode="json", exclude={"plugins"})
            except (ValueError, OSError):
                self._specs[method] = None
            else:
                self._specs[method] = {k: v for k, v in _flat(spec).items() if k not in PER_EPISODE}
        return self._specs[method]

    def __call__(self, record: dict) -> tuple[str, str] | None:
        return self.problem(record)

    def problem(self, record: dict) -> tuple[str, str] | None:
        fmt = record.get("format")
        if not isinstance(fmt, int) or not 1 <= fmt <= FORMAT_VERSION:
            return "inconsistent", f"format {fmt!r}: this code writes format {FORMAT_VERSION} and reads 1 to {FORMAT_VERSION}"
        rec = migrated(record)
        m, i, t = rec["method"], rec["intention"], rec["trial"]
        if m not in self.methods:
            return "plan", f"method {m!r} is not one of this folder's ({', '.join(sorted(self.methods))})"
        if i not in self.intentions:
            return "plan", f"intention {i!r} is not one of this folder's"
        if t >= self.trials:
            return "plan", f"trial {t} is past this folder's {self.trials} trial(s) (0 to {self.trials - 1})"
        planned, config = self.spec(m), rec.get("config")
        if planned is not None and isinstance(config, dict) and isinstance(config.get("spec"), dict):
            got = _flat(config["spec"])
            changed = [f"{k} {got.get(k, '(missing)')!r} (planned {v!r})" for k, v in planned.items()
                       if got.get(k, _MISSING) != v]
            changed += [f"{k} {rec[k]!r} (its spec's {got.get(path)!r})" for k, path in SPEC_COPIES.items()
                        if k in rec and rec[k] != got.get(path)]
            if changed:
                return "plan", "not made with this folder's settings: " + "; ".join(changed)
        seed, test_seed = trial_seeds(self.seed, i, t)
        test_seed = _test_stream(test_seed)
        is_error = bool(rec.get("error"))
        for name, want in (("seed", seed), ("test_seed", test_seed)):
            if (not is_error or name in rec) and rec.get(name) != want:
                return "plan", f"{name} {rec.get(name)!r} is not trial {t}'s ({want})"
        if is_error:
            return None
        curve = rec.get("success_at") or []
        if len(curve) != self.budget + 1:
            return "inconsistent", f"success_at has {len(curve)} points, not K + 1 = {self.budget + 1}"
        if rec.get("success") != curve[-1]:
            return "inconsistent", f"success {rec.get('success')!r} is not its own curve's last value {curve[-1]!r}"
        if fmt >= 3:
            problem = provenance_problem(rec.get("provenance"))
            if problem:
                return "inconsistent", f"provenance: {problem}"
        return None


@memoized(4096, "a trial's test seed → its test-scene stream: a pure function")
def _test_stream(test_seed: int) -> int:
    """The test seed an episode records: its test-scene stream (it depends on the trial's test
    seed only, so the episode seed given here does not matter)."""
    return EpisodeSeeds.from_seed(0, test_seed).test


def provenance_problem(p: object) -> str | None:
    """Why a record's provenance is not one ``provenance.py`` could have written (None: it could)."""
    if not isinstance(p, dict):
        return "missing" if p is None else f"not an object but {type(p).__name__}"
    commit, dirty, date = p.get("commit"), p.get("dirty"), p.get("date")
    if commit is not None and not (isinstance(commit, str) and _HEX40.fullmatch(commit)):
        return f"commit {commit!r} is not a git commit id"
    if dirty is not None and not isinstance(dirty, bool):
        return f"dirty {dirty!r} is not true or false"
    if commit is None and dirty is not None:
        return "dirty without a commit"
    try:
        when = dt.datetime.fromisoformat(date) if isinstance(date, str) else None
    except ValueError:
        when = None
    if when is None or when.tzinfo is None:
        return f"date {date!r} is not an ISO date with a time zone"
    if when > dt.datetime.now(dt.UTC) + _FUTURE_SLACK:
        return f"date {date} is in the future"
    if isinstance(commit, str) and not commit_known(commit):
        return f"commit {commit[:10]} is not in this checkout's history"
    return None


@memoized(1, "no key: this code's checkout (it does not move while the process runs)")
def _checkout() -> Path | None:
    """The git checkout this code runs from, when it is a full one (a shallow clone may lack
    the commits of older results: their commits are then not checked)."""
    root = Path(__file__).resolve().parents[3]
    try:
        out = subprocess.run(["git", "-C", str(root), "rev-parse", "--is-shallow-repository"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return root if out.returncode == 0 and out.stdout.strip() == "false" else None


@memoized(4096, "a commit id → whether the checkout holds it (a commit once there stays there)")
def commit_known(commit: str) -> bool:
    """True when this checkout holds the commit, or when there is no full checkout to ask."""
    root = _checkout()
    if root is None:
        return True
    try:
        out = subprocess.run(["git", "-C", str(root), "cat-file", "-e", f"{commit}^{{commit}}"],
                             capture_output=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return True
    return out.returncode == 0
