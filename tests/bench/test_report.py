"""The report and its figure: fixed colours, labelled bands, the protocol in the title, small
multiples, intervals in every table, paired comparisons against the best baseline."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from activeintent.bench import report
from activeintent.bench.report import (
    PANEL_METHODS,
    method_colour,
    paired_bootstrap,
    panel_groups,
    plot_success_vs_signals,
    sign_test,
    wilson,
    write_report,
)
from activeintent.learners.registry import method_names

SETTINGS = {"env": "symbolic", "user": "human", "budget": 2, "trials": 4}


def records_of(methods: list[str], intentions=("stack", "align"), trials: int = 4) -> list[dict]:
    """Synthetic episodes: method i succeeds more the later it is listed, so comparisons have a sign."""
    out = []
    for i, m in enumerate(methods):
        for intention in intentions:
            for t in range(trials):
                v = min(1.0, 0.1 * i + 0.05 * t)
                out.append({"method": m, "intention": intention, "trial": t, "success": v,
                            "success_at": [0.0, v / 2, v], "signals_used": 2, "answers": {"stop": 2}})
    return out


def plotted_colours(monkeypatch, methods: list[str], tmp_path) -> dict[str, str]:
    """The colour each method's line was drawn in (a spy on Axes.plot)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.axes import Axes
    from matplotlib.colors import to_hex

    seen: dict[str, str] = {}
    real = Axes.plot

    def spy(self, *args, **kwargs):
        lines = real(self, *args, **kwargs)
        for line in lines:
            seen[line.get_label().split(" (n=")[0]] = to_hex(line.get_color())
        return lines

    monkeypatch.setattr(Axes, "plot", spy)
    tmp_path.mkdir(exist_ok=True)
    plot_success_vs_signals(records_of(methods), methods, 2, tmp_path, settings=SETTINGS)
    monkeypatch.undo()  # the next figure gets its own spy
    return seen


def test_a_method_has_the_same_colour_in_every_figure(monkeypatch, tmp_path):
    one = plotted_colours(monkeypatch, ["bayes-stop", "zero-signal", "random-query"], tmp_path / "one")
    two = plotted_colours(monkeypatch, ["lang-stop", "random-query", "bayes-preference", "bayes-stop"], tmp_path / "two")
    assert set(one) == {"bayes-stop", "zero-signal", "random-query"}
    for m in set(one) & set(two):
        assert one[m] == two[m] == method_colour(m), m
    # no two built-in methods share one (plug-ins that earlier tests loaded hash into the spare colours)
    import subprocess
    import sys

    built_in = subprocess.run([sys.executable, "-c", "from activeintent.learners.registry import method_names; "
                               "print(' '.join(method_names()))"], capture_output=True, text=True, check=True)
    names = built_in.stdout.split()
    assert names and set(names) <= set(method_names())
    assert len({method_colour(m) for m in names}) == len(names)
    assert method_colour("my-plugin-method") == method_colour("my-plugin-method")


def test_panels_hold_at_most_four_methods_with_the_baselines_in_each():
    methods = ["bayes-stop", "bayes-preference", "lang-stop", "lang-preference", "decide-stop", "zero-signal",
               "random-query"]
    groups = panel_groups(methods)
    assert len(groups) > 1 and all(len(g) <= PANEL_METHODS for g in groups)
    assert sorted({m for g in groups for m in g}) == sorted(methods)
    assert all({"zero-signal", "random-query"} <= set(g) for g in groups)
    assert panel_groups(methods[:4]) == [methods[:4]]


def test_the_figure_has_small_multiples_labelled_bands_and_the_protocol_in_its_title(monkeypatch, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figures = []
    monkeypatch.setattr(plt, "close", lambda fig: figures.append(fig))
    methods = ["bayes-stop", "bayes-preference", "lang-stop", "lang-preference", "zero-signal"]
    plot_success_vs_signals(records_of(methods), methods, 2, tmp_path, settings=SETTINGS)
    fig = figures[0]
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert len(panels) == 2
    for ax in panels:
        names = [t.get_text() for t in ax.get_legend().get_texts()]
        assert "band: 95 % Wilson interval" in names and len(names) - 1 <= PANEL_METHODS
    title = fig._suptitle.get_text()
    assert "suite paper" in title and "user human" in title and "K = 2" in title and "4 trials" in title


CI = r"([0-9.]+) \[([0-9.]+), ([0-9.]+)\]"


def test_success_at_k_cells_carry_wilson_intervals_and_the_title_the_protocol(tmp_path):
    methods = ["bayes-stop", "zero-signal"]
    records = records_of(methods)
    text = write_report(records, methods, ["stack", "align"], tmp_path, SETTINGS).read_text()
    assert text.splitlines()[0] == "# activeintent benchmark — suite paper · user human · K = 2 signals · 4 trials · env symbolic"
    section = text.split("## success@k")[1].split("##")[0]
    row = next(line for line in section.splitlines() if line.startswith("| bayes-stop |"))
    cells = re.findall(CI, row)
    assert len(cells) == 3 and "| 8 |" in row
    for k, (mean, lo, hi) in enumerate(cells):
        vals = [r["success_at"][k] for r in records if r["method"] == "bayes-stop"]
        assert float(mean) == pytest.approx(round(float(np.mean(vals)), 2))
        assert (float(lo), float(hi)) == pytest.approx(tuple(round(x, 2) for x in wilson(sum(vals), len(vals))))
    header = next(line for line in text.splitlines() if line.startswith("| method | stack |"))
    assert "test scenes excluded (mean / episode)" in header and "signals used (mean / episode)" in header
    assert "**test scenes excluded**:" in text  # the column legend says what it counts


def test_every_method_is_paired_against_the_best_baseline(tmp_path):
    methods = ["bayes-stop", "lang-stop", "zero-signal", "random-query"]  # random-query scores best of the baselines
    records = records_of(["zero-signal", "bayes-stop", "random-query", "lang-stop"])
    assert report.best_baseline(records, methods) == "random-query"
    text = write_report(records, methods, ["stack", "align"], tmp_path, SETTINGS).read_text()
    section = text.split("## Paired comparisons")[1]
    assert "best baseline here, **random-query**" in section
    rows = [line for line in section.splitlines() if line.startswith("| ") and " − " in line and "method −" not in line]
    assert [r.split(" | ")[0] for r in rows] == ["| bayes-stop − random-query", "| lang-stop − random-query"]
    lang = rows[1]
    assert "8 / 0 / 0" in lang and f"{sign_test(8, 0):.3g}" in lang
    assert not any(report.is_baseline(m) for m in ("bayes-stop", "lang-stop"))


def paired_rows(methods: list[str], tmp_path) -> tuple[str, list[str]]:
    """The report's paired section for synthetic episodes of ``methods``, and its row names."""
    text = write_report(records_of(methods), methods, ["stack", "align"], tmp_path, SETTINGS).read_text()
    section = text.split("## Paired comparisons")[1]
    return section, [line.split(" | ")[0] for line in section.splitlines() if line.startswith("| ") and " − " in line]


def test_every_learner_is_paired_with_the_reward_peer_of_its_signal(tmp_path):
    section, rows = paired_rows(["bayes-stop", "lang-stop", "reward-stop", "reward-stop-noplanner", "zero-signal"],
                                tmp_path)
    assert "reward-learning peer of its signal (reward-stop)" in section
    assert "| bayes-stop − reward-stop" in rows and "| lang-stop − reward-stop" in rows
    assert not [r for r in rows if r.startswith("| reward-stop") and "zero-signal" not in r]  # not with itself
    assert report.peer_pairs(["bayes-preference", "reward-stop"]) == []  # only the peer of the same signal


def test_sign_test_and_paired_bootstrap():
    assert sign_test(8, 0) == pytest.approx(2 / 2**8)
    assert sign_test(3, 3) == 1.0 and sign_test(0, 0) == 1.0
    diffs = np.array([0.1, 0.2, 0.3, 0.2])
    lo, hi = paired_bootstrap(diffs)
    assert 0.1 <= lo <= diffs.mean() <= hi <= 0.3
    assert paired_bootstrap(diffs) == (lo, hi)  # fixed seed: the same report from the same records


def test_unscored_episodes_count_in_signals_answers_and_excluded_scenes(tmp_path):
    """An episode no test scene could score still asked and was answered: its signals, its "new
    scene" answers and its excluded scenes are in the suite table, beside the unscored count."""
    scored = {"method": "bayes-stop", "intention": "stack", "trial": 0, "success": 1.0, "success_at": [0.0, 1.0, 1.0],
              "signals_used": 2, "answers": {"stop": 2}, "test_excluded": 0}
    unscored = {**scored, "trial": 1, "success": None, "success_at": [None, None, None],
                "answers": {"new_scene": 2}, "test_excluded": 4}
    text = write_report([scored, unscored], ["bayes-stop"], ["stack"], tmp_path, SETTINGS).read_text()
    row = next(line for line in text.splitlines() if line.startswith("| bayes-stop |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[3:6] == ["2.0", "2/4", "2.0"] and cells[-1] == "1"


def test_a_hybrid_is_paired_with_the_language_learner_it_extends(tmp_path):
    from activeintent.registry import load_plugin

    load_plugin(Path(__file__).resolve().parents[2] / "experiments" / "hybrid" / "hybrid.py")  # as bench --plugin does
    section, rows = paired_rows(["lang-stop", "hybrid-stop", "hybrid-stop-map", "zero-signal"], tmp_path)
    assert "decide and hybrid against lang" in section
    assert "| hybrid-stop − lang-stop" in rows and "| hybrid-stop-map − lang-stop" in rows


def test_a_plug_in_method_brings_its_colour_and_its_pairing_in_its_registry_entry(monkeypatch, tmp_path):
    """Report colours and fixed pairs come from the methods' registry entries: a plug-in that
    registers a method with a colour and a method to compare with needs no change to the report."""
    from activeintent.learners.registry import METHODS, get_method

    base = get_method("bayes-stop")
    twin = replace(base, help="a plug-in twin of bayes-stop", colour="#123456", compared_with="bayes-stop")
    monkeypatch.setitem(METHODS._factories, "my-twin-stop", lambda: twin)
    assert report.method_colour("my-twin-stop") == "#123456"
    assert report.fixed_pairs(["my-twin-stop", "bayes-stop", "random-query"]) == [
        ("my-twin-stop", "bayes-stop"), ("bayes-stop", "random-query")]
    section, rows = paired_rows(["my-twin-stop", "bayes-stop", "zero-signal"], tmp_path)
    assert "| my-twin-stop − bayes-stop" in rows
    assert report.is_baseline("lang-zero-signal") and not report.is_baseline("lang-stop")
