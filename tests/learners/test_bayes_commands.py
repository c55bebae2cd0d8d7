"""`activeintent hypotheses` prints the size of H, the information floor and examples."""

from __future__ import annotations

import json
import math

from typer.testing import CliRunner

from activeintent.cli import app


def test_hypotheses_json():
    result = CliRunner().invoke(app, ["hypotheses", "--json", "--examples", "5"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.output)
    assert data["count"] >= 200
    assert data["information_floor"] == math.ceil(math.log(data["count"], 3))
    assert len(data["examples"]) == 5 and all(e["description"].endswith(".") for e in data["examples"])


def test_hypotheses_table():
    result = CliRunner().invoke(app, ["hypotheses", "--examples", "3"])
    assert result.exit_code == 0, result.output
    assert "distinct hypotheses" in result.output and "⌈log₃|H|⌉" in result.output
