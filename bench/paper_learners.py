"""Time the paper's learners end to end on the embedded model, model loading included.

    python bench/paper_learners.py [--budget 5] [--methods preference,mllm-llm] [--out DIR] [-- extra run options]

Runs ``activeintent run --method M --env symbolic --budget K --video none --cache-mode off``
once per method, each in a fresh process (so the model is loaded inside the time), and prints
per method: exit code, wall time, rounds, model calls, prompt and completion tokens, repairs
of the learner's calls, and the time split from summary.json. The target (issue 57) is exit 0
in at most 180 s each on 2 cores. A benchmark, not a test: the numbers depend on the machine
and on what else runs on it (``os.getloadavg()`` is printed beside them).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGET_S = 180


def run_one(method: str, budget: int, out: Path, extra: list[str]) -> dict:
    exe = shutil.which("activeintent") or str(Path(sys.executable).with_name("activeintent"))
    cmd = [exe, "run", "--method", method, "--env", "symbolic", "--budget", str(budget), "--video", "none",
           "--cache-mode", "off", "--out", str(out), *extra]
    load = os.getloadavg()[0]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, "COLUMNS": "200"})
    wall = time.perf_counter() - start
    row = {"method": method, "exit": proc.returncode, "wall_s": round(wall, 1), "load_before": round(load, 2),
           "command": " ".join(["activeintent", *cmd[1:]])}
    summary = out / "summary.json"
    if summary.exists():
        s = json.loads(summary.read_text())
        row.update(rounds=s.get("rounds_used"), llm_calls=s.get("llm_calls"), prompt_tokens=s.get("prompt_tokens"),
                   completion_tokens=s.get("completion_tokens"), episode_s=s.get("wall_s"),
                   time_split=s.get("time_split"), success=s.get("success"), error=s.get("error"))
    if proc.returncode:
        row["stderr_tail"] = (proc.stderr or proc.stdout)[-600:]
    row["table"] = proc.stdout[-3000:]
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=int, default=5)
    ap.add_argument("--methods", default="preference,mllm-llm")
    ap.add_argument("--out", type=Path, default=None, help="keep the runs' folders here")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--show-table", action="store_true", help="print each run's closing table")
    ap.add_argument("extra", nargs="*", help="more `run` options (after --)")
    args = ap.parse_args()
    root = args.out or Path(tempfile.mkdtemp(prefix="paper-bench-"))
    rows = [run_one(m, args.budget, root / m, args.extra) for m in args.methods.split(",")]
    if args.json:
        print(json.dumps({"cores": os.cpu_count(), "target_s": TARGET_S, "runs": rows}, indent=2))
        return
    print(f"paper learners on the embedded model, {os.cpu_count()} cores, target: exit 0 in <= {TARGET_S} s each")
    for r in rows:
        ok = "ok" if r["exit"] == 0 and r["wall_s"] <= TARGET_S else "MISSED"
        print(f"{r['method']:>10}: exit {r['exit']}, {r['wall_s']:.1f} s [{ok}] (load {r['load_before']}) · "
              f"{r.get('rounds')} rounds · {r.get('llm_calls')} model calls · "
              f"{r.get('prompt_tokens')}+{r.get('completion_tokens')} tokens · split {r.get('time_split')}")
        print(f"{'':>12}{r['command']}")
        if r["exit"]:
            print(f"{'':>12}{r.get('stderr_tail', '').strip()[-300:]}")
        if args.show_table:
            print(r["table"])


if __name__ == "__main__":
    main()
