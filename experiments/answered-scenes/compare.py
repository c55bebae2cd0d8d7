"""Each answered-scenes arm against today's default (fitted prior, sampled scenes, language 2:
docs/results/dev-lang2) on the same dev episodes: success@10, paired difference in area under
success@k (k = 0..10), and the "new scene" share of all answers. Run from the repository's root:

    .venv/bin/python experiments/answered-scenes/compare.py [RESULTS_ROOT]

RESULTS_ROOT holds one folder per arm, dev-<design> (default: this experiment's results/).
Writes comparison.md and comparison.json beside this file.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from activeintent.bench.report import arm_row, paired_comparison
from activeintent.results import read_results

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
BASELINE = "sampled"
LEARNERS = ("lang-stop", "lang-preference")


def arm_records(root: Path) -> dict[str, list[dict]]:
    out = {BASELINE: [r for r in read_results(REPO / "docs" / "results" / "dev-lang2" / "results.jsonl")
                      if r["method"] in LEARNERS]}
    for folder in sorted(root.glob("dev-*")):
        if (folder / "results.jsonl").is_file():
            out[folder.name.removeprefix("dev-")] = list(read_results(folder / "results.jsonl"))
    if len(out) == 1:
        raise SystemExit(f"no arm under {root}")
    return out


def summary(records: dict[str, list[dict]]) -> dict:
    pooled = [{**r, "method": f"{r['method']}@{arm}"} for arm, rs in records.items() for r in rs]
    rows, paired = [], []
    for arm, rs in records.items():
        for method in LEARNERS:
            rows.append({"arm": arm, **arm_row(rs, method)})
            if arm != BASELINE:
                c = paired_comparison(pooled, f"{method}@{arm}", f"{method}@{BASELINE}")
                if c is not None:
                    paired.append({"arm": arm, "method": method, **c})
    return {"baseline": "docs/results/dev-lang2 (fitted prior, sampled scenes, language 2)", "rows": rows, "paired": paired}


def markdown(s: dict) -> str:
    lines = ["# Answered tables on dev", "",
             "success@10, mean over episodes [95 % Wilson interval] (n = episodes); area: mean area under "
             "success@k, k = 0..10; new scene: share of all answers (count / answers).", "",
             "| scenes | method | success@10 | area | new scene |", "|---|---|---|---|---|"]
    for r in s["rows"]:
        lines.append(f"| {r['arm']} | {r['method']} | {r['success']:.2f} [{r['lo']:.2f}, {r['hi']:.2f}] (n = {r['n']}) "
                     f"| {r['area']:.3f} | {100 * r['new_scene_share']:.0f} % ({r['new_scene']} / {r['answers']}) |")
    lines += ["", f"Paired against {s['baseline']} on the same (intention, trial): difference in area, mean "
              "[95 % normal interval]; wins / ties / losses; success@10 difference [paired bootstrap].", "",
              "| scenes | method | Δ area | w / t / l | Δ success@10 |", "|---|---|---|---|---|"]
    for p in s["paired"]:
        lines.append(f"| {p['arm']} | {p['method']} | {p['mean']:+.3f} [{p['lo']:+.3f}, {p['hi']:+.3f}] "
                     f"(n = {p['n']}) | {p['wins']} / {p['ties']} / {p['losses']} | "
                     f"{p['final_mean']:+.3f} [{p['final_lo']:+.3f}, {p['final_hi']:+.3f}] |")
    return "\n".join(lines) + "\n"


def main() -> None:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "results"
    s = summary(arm_records(root))
    (HERE / "comparison.json").write_text(json.dumps(s, indent=1) + "\n")
    (HERE / "comparison.md").write_text(markdown(s))
    print(markdown(s))


if __name__ == "__main__":
    main()
