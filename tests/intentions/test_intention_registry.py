"""Finding intentions by name and loading user-defined ones from files (good and bad)."""

import textwrap
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from activeintent.cli.intentions import register
from activeintent.intentions import (
    INTENTION_NAMES,
    PAPER_INTENTIONS,
    Intention,
    IntentionError,
    get_intention,
    load_intention_file,
    resolve_intention,
)
from activeintent.world import WorldState, apply_plan, layout

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "my_intention.py"


def test_get_intention_by_name_and_normalised_spelling():
    assert get_intention("color-match").name == "color-match"
    assert get_intention(" Color_Match ").name == "color-match"
    assert set(PAPER_INTENTIONS) <= set(INTENTION_NAMES)


def test_unknown_intention_lists_valid_names():
    with pytest.raises(IntentionError) as err:
        get_intention("colour-match")
    message = str(err.value)
    assert "'colour-match'" in message and "Did you mean 'color-match'" in message
    for name in INTENTION_NAMES:
        assert name in message
    assert "--intention-file" in message


def test_resolve_intention():
    assert resolve_intention("stack", None).name == "stack"
    assert resolve_intention(None, f"{EXAMPLE}:RightmostBowl").name == "rightmost-bowl"
    with pytest.raises(IntentionError, match="not both"):
        resolve_intention("stack", f"{EXAMPLE}:RightmostBowl")
    with pytest.raises(IntentionError, match="No intention given"):
        resolve_intention(None, None)


def test_example_file_is_a_working_intention():
    intention = load_intention_file(f"{EXAMPLE}:RightmostBowl")
    assert isinstance(intention, Intention)
    assert intention.description
    for seed in range(5):
        scene = intention.sample_scene(np.random.default_rng(seed))
        assert intention.feasible(scene)
        state = WorldState(positions=layout(scene, seed))
        plan = intention.plan(state)
        states, failures = apply_plan(state, plan)
        assert failures == [None] * len(plan)
        assert intention.satisfied(states[-1] if states else state)
    # Without :NAME the file's only intention is used.
    assert load_intention_file(str(EXAMPLE)).name == "rightmost-bowl"


GOOD_BODY = """
from activeintent.intentions.base import Intention
from activeintent.world import Scene, sample_scene

class Never(Intention):
    {name_line}
    description = "Nothing ever pleases this user."
    def satisfied(self, state): return False
    def score(self, state): return 0.0
    def feasible(self, scene): return True
    def sample_scene(self, rng): return sample_scene(rng)
    def plan(self, state): return None
"""


def write(tmp_path: Path, text: str, name: str = "mine.py") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_class_instance_and_factory_are_accepted(tmp_path):
    body = GOOD_BODY.format(name_line='name = "never"')
    path = write(tmp_path, body + "\nINSTANCE = Never()\n\ndef make():\n    return Never()\n")
    assert load_intention_file(f"{path}:Never").name == "never"
    assert load_intention_file(f"{path}:INSTANCE").name == "never"
    assert load_intention_file(f"{path}:make").name == "never"


def test_missing_name_attribute_is_taken_from_the_identifier(tmp_path):
    path = write(tmp_path, GOOD_BODY.format(name_line="pass"))
    assert load_intention_file(f"{path}:Never").name == "never"


@pytest.mark.parametrize(
    "body, spec_name, expected",
    [
        (GOOD_BODY.format(name_line="pass") + "\nTHING = 42\n", "THING", r"THING is a int \(42\).*expected a subclass"),
        (GOOD_BODY.format(name_line="pass") + "\nclass Other:\n    pass\n", "Other",
         r"the class Other \(not a subclass.*expected"),
        (GOOD_BODY.format(name_line="pass") + "\ndef make():\n    return 'x'\n", "make", r"make\(\) returned a str"),
        (GOOD_BODY.format(name_line="pass"), "Missing", r"defines no 'Missing' \(intentions found in the file: Never\)"),
        ("from activeintent.intentions.base import Intention\n"
         "class Half(Intention):\n    description = 'x.'\n    def score(self, s): return 0.0\n",
         "Half", r"Half does not implement feasible, plan, sample_scene, satisfied"),
        ("def broken(:\n", "X", r"running mine.py failed: SyntaxError"),
        ("raise RuntimeError('boom')\n", "X", r"running mine.py failed: RuntimeError: boom"),
        (GOOD_BODY.format(name_line="pass").replace('"Nothing ever pleases this user."', '""'), "Never",
         r"Never has no description"),
    ],
)
def test_bad_intention_files_give_clear_errors(tmp_path, body, spec_name, expected):
    path = write(tmp_path, body)
    with pytest.raises(IntentionError, match=expected):
        load_intention_file(f"{path}:{spec_name}")


def test_missing_file_and_wrong_suffix(tmp_path):
    with pytest.raises(IntentionError, match="no such file"):
        load_intention_file(f"{tmp_path / 'nope.py'}:X")
    with pytest.raises(IntentionError, match="expected a Python file"):
        load_intention_file(f"{tmp_path / 'intent.txt'}:X")


def test_ambiguous_file_without_name(tmp_path):
    body = GOOD_BODY.format(name_line="pass") + "\nclass Also(Never):\n    pass\n"
    path = write(tmp_path, body)
    with pytest.raises(IntentionError, match=r"say which intention.*Never, Also"):
        load_intention_file(str(path))


def _cli() -> typer.Typer:
    app = typer.Typer()
    register(app)

    @app.callback()
    def _root() -> None:
        pass

    return app


def test_intentions_command_lists_all_and_user_file():
    runner = CliRunner()
    result = runner.invoke(_cli(), ["intentions"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    for name in INTENTION_NAMES:
        assert name in result.output
    assert "paper" in result.output and "--intention-file" in result.output
    result = runner.invoke(_cli(), ["intentions", "--intention-file", f"{EXAMPLE}:RightmostBowl"],
                           env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    assert "rightmost-bowl" in result.output
    result = runner.invoke(_cli(), ["intentions", "--intention-file", f"{EXAMPLE}:Nope"], env={"COLUMNS": "200"})
    assert result.exit_code == 2
    assert "defines no 'Nope'" in result.output


def test_grammar_only_example_intentions_load_and_are_not_named_ones():
    from pathlib import Path

    from activeintent.intentions.registry import INTENTION_NAMES, load_intention_file

    path = Path(__file__).resolve().parents[2] / "experiments" / "grammar-intentions" / "grammar_intentions.py"
    for name in ("PINK_BOWL", "NEXT_TO_YELLOW", "LEFT_SIDE", "WARM_LEFT_COOL_RIGHT"):
        intention = load_intention_file(f"{path}:{name}")
        assert intention.name not in INTENTION_NAMES and intention.description


def test_a_plugin_file_registers_an_intention_that_names_resolve(tmp_path):
    """Intentions are a registry like the other plug-in points: a --plugin file registers one,
    and --intention NAME finds it (labelled as a plug-in's, never as a suite's)."""
    from activeintent.registry import load_plugin
    from activeintent.suites import resolve, suite_of

    name = "never-from-a-plugin"
    body = GOOD_BODY.format(name_line=f'name = "{name}"')
    path = write(tmp_path, body + f'\nfrom activeintent.intentions import INTENTIONS\nINTENTIONS.register("{name}", Never)\n')
    with pytest.raises(IntentionError, match="Unknown intention"):
        resolve(name)
    load_plugin(path)
    intention = resolve(name)
    assert intention.name == name and intention.description == "Nothing ever pleases this user."
    assert suite_of(name) == "plugin"
    assert name not in INTENTION_NAMES  # the library suite stays the built-in one


def test_an_intention_file_takes_the_registered_name_as_well_as_the_class(tmp_path):
    """`--intention-file FILE:rightmost-bowl` (the name `intentions` prints) as well as FILE:RightmostBowl."""
    body = GOOD_BODY.format(name_line='name = "never-ever"')
    path = write(tmp_path, body)
    assert load_intention_file(f"{path}:never-ever").name == "never-ever"
    assert load_intention_file(f"{path}:Never").name == "never-ever"
    with pytest.raises(IntentionError, match="defines no 'always'"):
        load_intention_file(f"{path}:always")
