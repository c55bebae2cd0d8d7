"""The naturalness ablation (experiments/naturalness/naturalness.py): a language model's bits of z's
sentence, N(z), in the prior of lang-<signal>."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from activeintent.learners.bayes.belief import Belief
from activeintent.learners.lang.hypotheses import LangSpace
from activeintent.learners.registry import METHODS

PLUGIN = Path(__file__).parents[2] / "experiments" / "naturalness" / "naturalness.py"


@pytest.fixture
def ablation(monkeypatch):
    """The plug-in's module; its methods are registered only for this test (building one would
    score 3,000 sentences with the model, which a registry-wide test must not do)."""
    monkeypatch.setattr(METHODS, "_factories", dict(METHODS._factories))
    monkeypatch.setattr(METHODS, "_help", dict(METHODS._help))
    spec = importlib.util.spec_from_file_location("naturalness_ablation_under_test", PLUGIN)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert "lang-natural-stop" in METHODS
    return module


def test_the_model_finds_a_request_likelier_than_its_words_shuffled(ablation, tmp_path, monkeypatch):
    monkeypatch.setenv("ACTIVEINTENT_CACHE", str(tmp_path))
    sentence = "Every block goes in the bowl of its own colour."
    shuffled = "Colour bowl its goes block the every own in of."
    bits = ablation.sentence_bits([sentence, shuffled])
    assert 0 < bits[0] < bits[1] - 20
    # the second call reads the disk cache: no model is loaded
    monkeypatch.setattr("llama_cpp.Llama", None)
    assert ablation.sentence_bits([shuffled, sentence]).tolist() == bits[::-1].tolist()


def test_the_term_moves_prior_mass_toward_likelier_sentences_and_keeps_the_rest(ablation):
    from activeintent.goals.language import parse_goal

    keys = ["form tower:any all:", "form row:any all:", "every all: in-bowl:same"]
    space = LangSpace([parse_goal(k) for k in keys])
    belief = Belief(space.hypotheses)
    before = belief.log_w.copy()
    n_bits = np.array([40.0, 60.0, 80.0])
    weight = ablation.add_naturalness(belief, n_bits, 0.25)
    assert weight == 0.25
    # log-odds change by λ·ΔN·ln 2; the prior stays normalised
    assert (belief.log_w[0] - belief.log_w[1]) - (before[0] - before[1]) == pytest.approx(0.25 * 20 * math.log(2))
    assert np.exp(belief.log_w).sum() == pytest.approx(1.0)
    # λ = None: the term gets the spread of the description lengths
    equal = Belief(space.hypotheses)
    lengths = np.array([h.bits for h in space.hypotheses])
    assert ablation.add_naturalness(equal, n_bits, None) == pytest.approx(lengths.std() / n_bits.std())


def test_goals_that_join_later_get_their_length_prior_on_the_same_scale(ablation):
    from activeintent.goals.language import parse_goal

    start = LangSpace([parse_goal("form tower:any all:"), parse_goal("form row:any all:")])
    later = LangSpace([parse_goal("every all: in-bowl:same")])
    belief = Belief(start.hypotheses)
    ablation.add_naturalness(belief, np.array([40.0, 60.0]), 0.25)
    belief.extend(later.hypotheses, np.zeros(1))
    # N of a goal that joins is taken as the start space's mean: its weight is 2^-L against
    # the normaliser of the start space's prior with the term
    raw_start = -np.array([h.bits for h in start.hypotheses]) * math.log(2) - 0.25 * np.array([-10.0, 10.0]) * math.log(2)
    expected = -later.hypotheses[0].bits * math.log(2) - np.logaddexp(np.logaddexp.reduce(raw_start),
                                                                         -later.hypotheses[0].bits * math.log(2))
    assert belief.log_w[2] == pytest.approx(expected)


def test_the_term_is_refused_after_an_answer(ablation):
    from activeintent.goals.language import parse_goal

    space = LangSpace([parse_goal("form tower:any all:"), parse_goal("form row:any all:")])
    belief = Belief(space.hypotheses)
    belief.update(np.array([0.9, 0.1]))
    with pytest.raises(ValueError, match="before any answer"):
        ablation.add_naturalness(belief, np.array([1.0, 2.0]), 0.25)


def test_the_committed_table_is_what_the_model_computes(ablation, tmp_path, monkeypatch):
    import json

    from activeintent.llm.embedded import default_gguf

    table = json.loads(ablation.TABLE.read_text())
    assert table["digest"] == ablation._digest(default_gguf()) and len(table["bits"]) == 3000
    sentences = list(table["bits"])[::1000]
    monkeypatch.setenv("ACTIVEINTENT_CACHE", str(tmp_path))
    monkeypatch.setattr(ablation, "TABLE", tmp_path / "none.json")  # computed anew, not read
    fresh = ablation.sentence_bits(sentences)
    assert fresh == pytest.approx([table["bits"][s] for s in sentences], abs=0.05)
