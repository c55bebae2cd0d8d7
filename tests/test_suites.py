"""Suites are a registry like the others: a user's suite is a plug-in."""

from __future__ import annotations

import pytest

from activeintent.intentions.registry import get_intention
from activeintent.suites import SUITE_NAMES, SUITES, Suite, is_held_out, resolve, suite, suite_of


def test_the_built_in_suites_are_the_registry_in_order():
    assert SUITE_NAMES == ("paper", "library", "heldout", "heldout2", "dev", "truth-goals")
    assert [n for n in SUITE_NAMES if is_held_out(n)] == ["heldout", "heldout2"]
    with pytest.raises(ValueError, match="valid suites: paper, library, heldout"):
        suite("nope")


def test_a_plug_in_suite_is_listed_resolved_and_kept_hidden_when_held_out():
    class Mine(type(get_intention("align"))):
        pass

    mine = Mine()
    mine.name = "my-lab-align"
    SUITES.register("my-lab", Suite(lambda: {mine.name: mine}, held_out=True), help="a lab's own")
    try:
        assert suite("my-lab") == ["my-lab-align"]
        assert suite_of("my-lab-align") == "my-lab" and is_held_out("my-lab")
        assert resolve("my-lab-align") is mine
    finally:
        SUITES._factories.pop("my-lab")
        SUITES._help.pop("my-lab")
    assert suite_of("my-lab-align") == "other"
