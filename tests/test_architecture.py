"""The layering the design promises, checked on the source: data flows one way, learners and
users never see each other, nothing above world/ imports the simulator, no import cycles."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "activeintent"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path) -> set[str]:
    """activeintent modules imported anywhere in ``path`` (``if TYPE_CHECKING:`` blocks too)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("activeintent")}
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("activeintent"):
            out.add(node.module)
            out |= {f"{node.module}.{a.name}" for a in node.names}
    return out


MODULES = {module_name(p): p for p in SRC.rglob("*.py")}


@pytest.mark.parametrize("package,forbidden", [
    ("activeintent.learners", ("activeintent.users", "activeintent.sim")),
    ("activeintent.users", ("activeintent.learners", "activeintent.sim.env", "activeintent.sim.render")),
    ("activeintent.signals", ("activeintent.users", "activeintent.learners", "activeintent.sim")),
    ("activeintent.world", ("activeintent.sim", "activeintent.learners", "activeintent.users", "activeintent.intentions")),
    ("activeintent.intentions", ("activeintent.learners", "activeintent.users", "activeintent.sim")),
    ("activeintent.goals", ("activeintent.learners", "activeintent.users", "activeintent.sim", "activeintent.intentions")),
    # written blind with the world's helpers only: expressible in the language is measured, not built in
    ("activeintent.suites.heldout", ("activeintent.goals",)),
])
def test_layering(package, forbidden):
    bad = [(name, imp) for name, path in MODULES.items() if name.startswith(package)
           for imp in imports(path) if imp.startswith(forbidden)]
    assert not bad, f"{package} must not import {forbidden}: {bad}"


def test_commands_live_in_cli_and_the_library_never_imports_it():
    """One module per command group under cli/; the library below defines no command (no typer)
    and never imports the command line."""
    commands = [name for name, path in MODULES.items() if not name.startswith("activeintent.cli")
                and re.search(r"^\s*(import typer|from typer)", path.read_text(), re.M)]
    assert not commands, f"commands outside activeintent.cli: {commands}"
    upward = [(name, imp) for name, path in MODULES.items() if not name.startswith("activeintent.cli")
              for imp in imports(path) if imp.startswith("activeintent.cli")]
    assert not upward, f"the library imports the command line: {upward}"


# The layers, bottom first: a module imports only from its own part (a top-level module or
# package) and from parts of lower layers, at any depth (inside functions and under
# TYPE_CHECKING too). docs/architecture.md draws the same order.
LAYERS = (
    ("memo",),  # the one in-process cache: every part may keep one
    ("registry", "provenance", "progress_lines", "ranking", "llm"),
    ("world",),
    ("act", "goals", "protocol", "signals", "sim"),
    ("envs", "intentions", "records", "spec"),
    ("learners", "results", "users"),
    ("scoring",),
    ("episode", "suites"),
    ("runner",),
    ("bench", "web"),
    ("cli",),
)
LAYER = {part: i for i, parts in enumerate(LAYERS) for part in parts}


# The parts of goals/, bottom first: a module of goals/ imports only goals modules of lower
# layers (the goal language's parts show in their order: node kinds, then node types, then goals).
GOALS_LAYERS = (
    ("facts", "planning"),
    ("nodes",),
    ("selectors", "relations"),
    ("structures",),
    ("goal", "requested", "recipes"),
    ("language", "planner", "prior"),
)


def test_the_goals_modules_import_down_their_layers():
    layer = {f"activeintent.goals.{m}": i for i, ms in enumerate(GOALS_LAYERS) for m in ms}
    goals = {name for name in MODULES if name.startswith("activeintent.goals.")}
    assert goals == set(layer), f"goals modules without a layer: {sorted(goals ^ set(layer))}"
    upward = sorted((name, imp) for name in goals for imp in imports(MODULES[name])
                    if imp in layer and layer[imp] >= layer[name])
    assert not upward, f"goals modules importing sideways or up: {upward}"


def part_of(module: str) -> str:
    return module.split(".")[1] if module.count(".") else module


def test_every_import_runs_down_the_layers():
    parts = {part_of(name) for name in MODULES} - {"activeintent", "prompts"}
    assert parts <= set(LAYER), f"parts without a layer: {sorted(parts - set(LAYER))}"
    upward = sorted((name, imp) for name, path in MODULES.items() for imp in imports(path)
                    if part_of(name) != part_of(imp) and part_of(imp) in LAYER and part_of(name) in LAYER
                    and LAYER[part_of(imp)] >= LAYER[part_of(name)])
    assert not upward, f"imports that do not run down the layers: {upward}"


def test_function_level_project_imports_are_few_and_say_why():
    """Imports of the project inside functions only keep a heavy dependency (PyBullet, FastAPI, the
    openai SDK) off paths that do not need it; each block says so in a ``# lazy:`` line above it."""
    found, unexplained = set(), []
    for name, path in MODULES.items():
        lines = path.read_text().splitlines()
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for stmt in ast.walk(node):
                if (name, getattr(stmt, "lineno", 0)) in found:
                    continue
                if isinstance(stmt, (ast.Import, ast.ImportFrom)) and any(
                        m.startswith("activeintent") for m in
                        ([stmt.module or ""] if isinstance(stmt, ast.ImportFrom) else [a.name for a in stmt.names])):
                    found.add((name, stmt.lineno))
                    above = stmt.lineno - 2
                    while above >= 0 and re.match(r"\s*(from|import) ", lines[above]):
                        above -= 1
                    if above < 0 or "# lazy:" not in lines[above]:
                        unexplained.append(f"{name}:{stmt.lineno}")
    assert len(found) <= 30, f"{len(found)} function-level project imports (at most 30)"
    assert not unexplained, f"function-level imports without a '# lazy:' reason above them: {unexplained}"


def _is_type_checking(node: ast.AST) -> bool:
    test = node.test if isinstance(node, ast.If) else None
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def runtime_imports(path: Path) -> set[str]:
    """activeintent modules ``path`` may import when it runs: module level, inside functions and
    methods (lazy imports run on first call) and in try blocks. Imports under
    ``if TYPE_CHECKING:`` are left out: they never run, so they cannot form a cycle at run time
    (their ``else:`` branch does run and counts)."""
    out: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _is_type_checking(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("activeintent"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("activeintent"):
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(path.read_text()))
    return out


def import_graph() -> dict[str, set[str]]:
    graph = {name: {m for m in runtime_imports(path) if m in MODULES and m != name}
             for name, path in MODULES.items()}
    # a package's __init__ importing its own submodules is not a cycle of meaning
    for name in graph:
        graph[name] = {m for m in graph[name] if not (MODULES[name].name == "__init__.py" and m.startswith(name + "."))}
    return graph


def import_cycles(graph: dict[str, set[str]]) -> set[frozenset[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, cycles, counter = {}, {}, [], set(), set(), [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.add(frozenset(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return cycles


# Import cycles allowed (none since issue 30: a registry lives in its own module, not in the
# base its entries import). Lazy (function-level) imports count as imports.
KNOWN_IMPORT_CYCLES: frozenset[frozenset[str]] = frozenset()


def test_no_import_cycles():
    cycles = import_cycles(import_graph())
    new = [sorted(c) for c in cycles - KNOWN_IMPORT_CYCLES]
    assert not new, f"new import cycles (function-level imports count): {new}"
    gone = [sorted(c) for c in KNOWN_IMPORT_CYCLES - cycles]
    assert not gone, f"these known cycles no longer exist: remove them from KNOWN_IMPORT_CYCLES: {gone}"


def test_the_cycle_check_sees_lazy_imports_and_ignores_type_checking_blocks(tmp_path):
    code = (
        "from typing import TYPE_CHECKING\n"
        "import activeintent.a\n"
        "if TYPE_CHECKING:\n"
        "    from activeintent.b import B\n"
        "else:\n"
        "    import activeintent.c\n"
        "def f():\n"
        "    from activeintent.d import g\n"
        "class K:\n"
        "    def m(self):\n"
        "        import activeintent.e\n"
        "try:\n"
        "    import activeintent.h\n"
        "except ImportError:\n"
        "    pass\n"
    )
    (tmp_path / "m.py").write_text(code)
    found = runtime_imports(tmp_path / "m.py")
    assert found == {"activeintent.a", "activeintent.c", "activeintent.d", "activeintent.d.g",
                     "activeintent.e", "activeintent.h"}
    graph = {"x": {"y"}, "y": {"z"}, "z": {"x"}, "w": {"x"}}
    assert import_cycles(graph) == {frozenset({"x", "y", "z"})}


def test_one_episode_loop_and_no_proxies():
    loops = [name for name, path in MODULES.items() if "def run_symbolic_episode" in path.read_text()]
    assert not loops
    web = [name for name, path in MODULES.items() if name.startswith("activeintent.web")
           and "def __getattr__" in path.read_text()]
    assert not web, f"web proxies the episode through __getattr__: {web}"


def test_every_plug_in_point_is_one_registry():
    """Methods, signals, envs, user presets, intentions, executors and the goal language's node
    types are each a registry.Registry; no module keeps a name table of its own for them."""
    from activeintent.act.executors import EXECUTORS
    from activeintent.envs.base import ENVS
    from activeintent.goals.language import NODES
    from activeintent.intentions.registry import INTENTIONS
    from activeintent.learners.registry import METHODS
    from activeintent.registry import Registry
    from activeintent.signals.registry import SIGNALS
    from activeintent.users.simulated import USER_PRESETS

    points = [METHODS, SIGNALS, ENVS, USER_PRESETS, INTENTIONS, EXECUTORS, *NODES.values()]
    assert all(isinstance(p, Registry) for p in points)
    assert all(len(p) > 0 for p in points)
    second = [name for name, path in MODULES.items() if name != "activeintent.registry"
              and re.search(r"^class \w*Registry\b|^_BUILTIN\b", path.read_text(), re.M)]
    assert not second, f"a second registry: {second}"


def test_one_vocabulary_of_goals():
    """The bayes grammar's leaves are nodes of the goal language (goals/), not a second vocabulary
    of its own: learners/bayes/behaviours.py is gone, hypotheses.py imports its leaves from goals/
    and nothing else of the learners, and every leaf is built from goals classes."""
    assert not (SRC / "learners" / "bayes" / "behaviours.py").exists()
    grammar = imports(MODULES["activeintent.learners.bayes.hypotheses"])
    assert {"activeintent.goals.relations", "activeintent.goals.structures", "activeintent.goals.recipes"} <= grammar
    assert not [m for m in grammar if m.startswith("activeintent.learners")], grammar

    from activeintent.goals.recipes import Leaf
    from activeintent.learners.bayes.hypotheses import ALL_FAMILIES

    for family, behaviours in ALL_FAMILIES:
        for b in behaviours:
            assert isinstance(b.leaf, Leaf), family
            parts = [b.leaf] + [getattr(b.leaf, a) for a in ("rel", "struct") if hasattr(b.leaf, a)]
            parts += [p.inner for p in parts if hasattr(p, "inner")]  # Flat(NextTo()) and the like
            assert all(type(p).__module__.startswith("activeintent.goals.") for p in parts), (family, parts)


# The goal language's parts (goals/language.py is their public face).
LANGUAGE_PARTS = ("nodes", "selectors", "relations", "structures", "goal")
LANGUAGE = {str(SRC / "goals" / f"{part}.py") for part in LANGUAGE_PARTS}


def _language_calls(call) -> set[str]:
    """The functions of the goal language's parts that ``call()`` runs (nodes judging the state)."""
    import sys

    seen: set[str] = set()

    def profile(frame, event, arg):
        if event == "call" and frame.f_code.co_filename in LANGUAGE:
            seen.add(frame.f_code.co_name)

    sys.setprofile(profile)
    try:
        call()
    finally:
        sys.setprofile(None)
    return seen


def _library_and_dev_intentions():
    from activeintent.intentions.registry import INTENTION_NAMES, get_intention
    from activeintent.suites.dev import dev_intentions

    return [get_intention(n) for n in INTENTION_NAMES] + dev_intentions()


@pytest.mark.parametrize("intention", _library_and_dev_intentions(), ids=lambda i: i.name)
def test_library_and_dev_intentions_take_their_meaning_from_the_goal_language(intention):
    """The library intentions and the dev suite judge a state with goals nodes (satisfied, score,
    whether a step moves away), not with predicates of their own; scenes and oracle plans are the
    protocol's and may stay in intentions/."""
    import numpy as np

    from activeintent.intentions.base import Intention
    from activeintent.intentions.blockwise import BlockwiseIntention
    from activeintent.world import PutAt, WorldState, apply_skill, relations
    from activeintent.world.scene import layout

    module = type(intention).__module__
    assert {f"activeintent.goals.{part}" for part in LANGUAGE_PARTS} & imports(MODULES[module]), module
    state = WorldState(positions=layout(intention.sample_scene(np.random.default_rng(0)), 0))
    step = (intention.plan(state) or [PutAt(block=state.blocks[0], position="middle")])[0]
    after, failure = apply_skill(state, step)
    assert failure is None and intention.score(after) >= intention.score(state)  # no early "score drops"
    assert _language_calls(lambda: intention.satisfied(after)), f"{intention.name}.satisfied"
    assert _language_calls(lambda: intention.score(after)), f"{intention.name}.score"
    if isinstance(intention, BlockwiseIntention):  # where each block is wanted
        assert _language_calls(lambda: intention.wanted(after, relations(after), step.block)), intention.name
    own_move_rule = type(intention).step_moves_away not in (Intention.step_moves_away, BlockwiseIntention.step_moves_away)
    if own_move_rule:  # beyond a drop in score, the node says which moves go against it
        assert "moved_ok" in _language_calls(lambda: intention.step_moves_away(state, after, step)), intention.name


def module_closure(name: str) -> dict[str, str]:
    """The activeintent modules ``name`` imports at run time, directly or through the modules
    it imports, each with the module that imports it. Parent packages' __init__ files that
    Python runs on the way are left out (activeintent.intentions registers the library, which is
    goals-based by design): what counts is the code the module asks for."""
    found: dict[str, str] = {}
    todo = [name]
    while todo:
        current = todo.pop()
        for m in sorted(runtime_imports(MODULES[current])):
            if m in MODULES and m not in found and m != name:
                found[m] = current
                todo.append(m)
    return found


@pytest.mark.parametrize("suite", ["heldout", "heldout2"])
def test_held_out_suites_stay_independent_of_the_goal_language(suite):
    """Written blind with the world's helpers only (also at run time: lazy imports count, and
    the modules they import, transitively), so that whether the language can say them is
    measured, not true by construction."""
    path = SRC / "suites" / f"{suite}.py"
    assert path.exists()
    found = imports(path) | runtime_imports(path)
    assert not [m for m in found if m.startswith("activeintent.goals")], found
    closure = module_closure(f"activeintent.suites.{suite}")
    assert {"activeintent.intentions.base", "activeintent.intentions.blockwise", "activeintent.intentions.placement",
            "activeintent.world"} <= set(closure)  # the walk reaches the helpers they share
    via = {m: closure[m] for m in closure if m.startswith("activeintent.goals")}
    assert not via, f"{suite} reaches the goal language through (module: imported by): {via}"


def test_every_path_the_architecture_doc_names_exists():
    """docs/architecture.md's layout and file names match the tree: each file or folder it names
    (in the layout block, or as `path.py` in its text) exists under src/activeintent or the root."""
    import re

    root = Path(__file__).resolve().parents[1]
    text = (root / "docs" / "architecture.md").read_text()
    layout = text.split("```\nsrc/activeintent/", 1)[1].split("```", 1)[0]
    named: set[str] = set()
    for line in ("src/activeintent/\n" + layout).splitlines():
        m = re.match(r"^(\s*)([\w.-]+/|[\w.-]+\.py)\s", line + " ")
        if not m:
            continue
        indent, name = len(m.group(1)), m.group(2)
        if indent == 0:
            if name != "src/activeintent/":
                named.add(name)
            continue
        if indent == 2:
            top = name
            named.add(top)
        elif indent == 4 and name.endswith("/"):
            named.add(f"{top}{name}")
    named |= set(re.findall(r"`((?:[\w-]+/)*[\w-]+\.(?:py|md|json|html|txt))`", text))
    named |= set(re.findall(r"\b[\w]+\.py\b", layout))  # every module the layout lists
    named -= {"summary.json", "rounds.jsonl", "results.jsonl", "bench.json"}  # files a run writes
    where = [root / "src" / "activeintent", root, root / "src" / "activeintent" / "learners", root / "examples"]
    src_files = [str(p) for p in (root / "src" / "activeintent").rglob("*")]
    missing = [n for n in sorted(named) if not any((w / n).exists() for w in where)
               and not any(f.endswith("/" + n) for f in src_files)]
    assert named and not missing, missing
