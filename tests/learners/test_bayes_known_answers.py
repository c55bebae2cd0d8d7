"""Known answers for the description-length prior, worked out by hand from docs/bayes.md.

These replace checks that recomputed the code's own formula: a wrong formula copied into a test
passes; a number worked out independently does not.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from activeintent.learners.bayes.hypotheses import enumerate_hypotheses, hypothesis_space, log_prior


def test_log_prior_of_a_toy_space():
    # lengths 1, 2, 2 bits: 2^-1 : 2^-2 : 2^-2 already sum to one
    toy = [SimpleNamespace(bits=1.0), SimpleNamespace(bits=2.0), SimpleNamespace(bits=2.0)]
    assert np.exp(log_prior(toy)) == pytest.approx([0.5, 0.25, 0.25])
    # lengths 3 and 4 bits: 1/8 : 1/16, renormalised to 2/3 : 1/3
    toy = [SimpleNamespace(bits=3.0), SimpleNamespace(bits=4.0)]
    assert np.exp(log_prior(toy)) == pytest.approx([2 / 3, 1 / 3])
    assert np.exp(log_prior([SimpleNamespace(bits=7.5)])) == pytest.approx([1.0])


# docs/bayes.md: one of 3 structures, one of 18 families for "all" (12 for one colour class,
# plus one bit for which class; 12 and then 11 rules for the pair), one of 10 colours.
@pytest.mark.parametrize(
    ("name", "bits"),
    [
        ("all:tower", 5.754888),  # log2 3 + log2 18
        ("all:in-bowl[red]", 9.076816),  # log2 3 + log2 18 + log2 10
        ("warm:tower", 6.169925),  # log2 3 + 1 + log2 12
        ("warm:tower+cool:in-any-bowl", 8.629357),  # log2 3 + log2 12 + log2 11
    ],
)
def test_description_lengths(name, bits):
    by_name = {h.name: h for h in enumerate_hypotheses()}
    assert by_name[name].bits == pytest.approx(bits, abs=1e-5)


def test_prior_ratios_in_the_deduplicated_space():
    space = hypothesis_space()
    index = {h.name: i for i, h in enumerate(space)}
    prior = np.exp(log_prior(space))
    tower = prior[index["all:tower"]]
    assert prior.sum() == pytest.approx(1.0)
    # one colour out of 10 costs a factor 10; a pair rule 12·11 / 18 = 22/3 against "all"
    assert tower / prior[index["all:in-bowl[red]"]] == pytest.approx(10.0)
    assert tower / prior[index["warm:tower+cool:in-any-bowl"]] == pytest.approx(22 / 3)
