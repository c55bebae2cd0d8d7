"""The defaults experiment's comparison: each (prior, scenes) arm against today's (length, sampled)
on the same dev episodes, in area under success@k (k = 0..10), per signal; and the rule that
picks the default. Run from the repository's root after run.sh:

    .venv/bin/python experiments/defaults/compare.py [RESULTS_ROOT [OUT]]

RESULTS_ROOT holds dev-length-belief, dev-fitted-sampled and dev-fitted-belief (default:
experiments/defaults/results); the baseline arm is docs/results/peer's lang-* dev episodes of
trials 0-9. Writes OUT/comparison.md and comparison.json (default: this experiment's folder).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from activeintent.bench.report import arm_row, paired_comparison
from activeintent.results import read_results

REPO = Path(__file__).resolve().parents[2]
ARMS = ("length-sampled", "length-belief", "fitted-sampled", "fitted-belief")
BASELINE = "length-sampled"
LEARNERS = ("lang-stop", "lang-preference")
TRIALS = 10


def arm_records(root: Path) -> dict[str, list[dict]]:
    """Every arm's records, methods named ``<method>@<arm>`` so that one list pairs them."""
    ran = [arm for arm in ARMS[1:] if (root / f"dev-{arm}" / "results.jsonl").is_file()]
    if not ran:
        raise SystemExit(f"no arm has run yet under {root} (run.sh makes them)")
    dev = set(json.loads((root / f"dev-{ran[0]}" / "bench.json").read_text())["intentions"])
    peer = [r for r in read_results(REPO / "docs" / "results" / "peer" / "results.jsonl")
            if r["method"] in LEARNERS and r["intention"] in dev and r["trial"] < TRIALS]
    out = {BASELINE: peer}
    for arm in ran:
        out[arm] = list(read_results(root / f"dev-{arm}" / "results.jsonl"))
    return out


def summary(records: dict[str, list[dict]]) -> dict:
    pooled = [{**r, "method": f"{r['method']}@{arm}"} for arm, rs in records.items() for r in rs]
    rows = []
    for arm, rs in records.items():
        for method in (*LEARNERS, "lang-zero-signal"):
            if (row := arm_row(rs, method)) is not None:
                rows.append({"arm": arm, **row})
    paired = []
    ran = [arm for arm in ARMS[1:] if arm in records]
    for arm in ran:
        for method in LEARNERS:
            c = paired_comparison(pooled, f"{method}@{arm}", f"{method}@{BASELINE}")
            if c is not None:
                paired.append({"arm": arm, "method": method, **c})
    eligible = [arm for arm in ran
                if all(p["mean"] >= 0 for p in paired if p["arm"] == arm)
                and sum(p["arm"] == arm for p in paired) == len(LEARNERS)]
    best = max(eligible, key=lambda arm: sum(p["mean"] for p in paired if p["arm"] == arm), default=None)
    missing = [arm for arm in ARMS[1:] if arm not in records]
    # the rule chooses among all arms: with one not run yet there is no choice to make
    default = None if missing else (best or BASELINE)
    return {"rows": rows, "paired": paired, "eligible": eligible, "missing": missing, "default": default}


def markdown(s: dict) -> str:
    lines = ["# Defaults on dev: prior × scenes", "",
             "success@10, mean over episodes [95 % Wilson interval] (n = episodes); area: mean area under "
             "success@k, k = 0..10; new scene: share of all answers.", "",
             "| arm (prior-scenes) | method | success@10 | area | new scene |", "|---|---|---|---|---|"]
    for r in s["rows"]:
        area = "–" if r["area"] is None else f"{r['area']:.3f}"
        share = "–" if r["new_scene_share"] is None else f"{100 * r['new_scene_share']:.0f} %"
        lines.append(f"| {r['arm']} | {r['method']} | {r['success']:.2f} [{r['lo']:.2f}, {r['hi']:.2f}] "
                     f"(n = {r['n']}) | {area} | {share} |")
    lines += ["", f"Paired against {BASELINE} on the same (intention, trial): difference in area, mean "
              "[95 % normal interval]; wins / ties / losses; success@10 difference [paired bootstrap].", "",
              "| arm | method | Δ area | w / t / l | Δ success@10 |", "|---|---|---|---|---|"]
    for p in s["paired"]:
        lines.append(f"| {p['arm']} | {p['method']} | {p['mean']:+.3f} [{p['lo']:+.3f}, {p['hi']:+.3f}] "
                     f"(n = {p['n']}) | {p['wins']} / {p['ties']} / {p['losses']} | "
                     f"{p['final_mean']:+.3f} [{p['final_lo']:+.3f}, {p['final_hi']:+.3f}] |")
    lines += ["", "Rule: an arm may become the default only if its paired mean is ≥ 0 for both signals; among "
              "those, the highest mean of the two wins.", "",
              f"Eligible: {', '.join(s['eligible']) or 'none'}. " + (
                  f"**Default: {s['default']}**." if s["default"] else
                  f"**No default chosen yet**: not run yet: {', '.join(s['missing'])}."), ""]
    return "\n".join(lines)


def main() -> None:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "experiments" / "defaults" / "results"
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path(__file__).resolve().parent
    s = summary(arm_records(root))
    (out / "comparison.json").write_text(json.dumps(s, indent=1) + "\n")
    (out / "comparison.md").write_text(markdown(s))
    print(markdown(s))


if __name__ == "__main__":
    main()
