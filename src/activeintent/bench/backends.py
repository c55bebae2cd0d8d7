"""Where the episodes of a bench run: ``local`` (a process pool on this machine, runner.py) or
``ray`` (one Ray task per episode, on a cluster or on a Ray started here).

Both backends run the same :func:`activeintent.bench.runner.run_item` and hand its records
back to the driver, which alone appends ``results.jsonl``: resume, progress and the
settings check are the same whichever backend ran an episode, and a bench may be resumed on
the other backend. An episode's record depends only on its options and seeds, so the same
bench gives the same records on both (apart from timings).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

from activeintent.bench.work import BenchConfig, WorkItem, run_item

BACKENDS = ("local", "ray")

# Variables a worker of an existing cluster would not otherwise see (its processes were started
# by `ray start`, not from this shell): the model endpoint and the project's own settings.
FORWARDED_PREFIXES = ("ACTIVEINTENT_",)
FORWARDED_NAMES = ("OPENAI_API_KEY", "OPENAI_BASE_URL", "OMP_WAIT_POLICY", "GOMP_SPINCOUNT")

# Tasks kept in flight per CPU of the cluster: enough to keep every worker busy, few enough that
# a killed driver loses little and a bench of 100 000 episodes is not one huge submission.
IN_FLIGHT_PER_CPU = 2
LOCAL_OBJECT_STORE = 256 * 2**20  # bytes, for a Ray started here


def check_backend(name: str) -> None:
    """Refuse, before any work, a backend that cannot run here."""
    if name not in BACKENDS:
        raise ValueError(f"--backend {name!r}: valid backends are {', '.join(BACKENDS)}")
    if name == "ray":
        import importlib.util

        if importlib.util.find_spec("ray") is None:
            raise ValueError("--backend ray needs Ray: pip install 'activeintent[ray]'")


def worker_died(item: WorkItem, options: BenchConfig, why: str = "worker process died") -> dict:
    """The record of an episode whose worker ended without an answer (e.g. a native crash)."""
    return {"method": item.method, "intention": item.intention, "trial": item.trial, "success": None, "error": why}


def forwarded_env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items()
            if k in FORWARDED_NAMES or k.startswith(FORWARDED_PREFIXES)}


def ray_address(options: BenchConfig) -> str | None:
    """--ray-address, else RAY_ADDRESS; None: start a Ray of our own on this machine."""
    return options.ray_address or os.environ.get("RAY_ADDRESS") or None


def _start_ray(options: BenchConfig) -> bool:
    """Connect (or start) Ray; True when this call did, so the caller shuts it down again."""
    import ray

    if ray.is_initialized():  # e.g. a notebook or a test that started Ray itself
        return False
    env = {"env_vars": forwarded_env()}
    address = ray_address(options)
    if address:
        ray.init(address=address, runtime_env=env, log_to_driver=False)
    else:
        # "local" always starts a fresh Ray, even when a `ray start` cluster runs here.
        # Records are small: a modest object store leaves the memory to the episodes.
        ray.init(address="local", num_cpus=options.jobs, include_dashboard=False,
                 object_store_memory=LOCAL_OBJECT_STORE, runtime_env=env, log_to_driver=False)
    return True


def execute_ray(todo: list[WorkItem], options: BenchConfig, out: Path) -> Iterator[dict]:
    """Yield one record per episode of ``todo``, in the order they finish."""
    import ray
    from ray.exceptions import RayError, RayTaskError

    if not todo:
        return
    started = _start_ray(options)
    try:
        # One CPU per episode; a worker that dies (a native crash, an out-of-memory kill, a lost
        # node) is retried once, and a second death is recorded as the episode's error.
        task = ray.remote(num_cpus=1, max_retries=1)(run_item)
        run = ray.put(options.run)
        cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
        window = IN_FLIGHT_PER_CPU * cpus
        queue = list(todo)
        pending: dict = {}
        while queue or pending:
            while queue and len(pending) < window:
                item = queue.pop(0)
                pending[task.remote(item, run, options.seed, str(out), options.keep_episodes)] = item
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                item = pending.pop(ref)
                try:
                    yield ray.get(ref)
                except RayTaskError as err:  # run_item records its own errors; this is anything else
                    yield worker_died(item, options, f"task failed: {getattr(err, 'cause', err)!r}")
                except RayError as err:  # the worker (or its node) is gone
                    yield worker_died(item, options, f"worker process died ({type(err).__name__})")
    finally:
        if started:
            ray.shutdown()
