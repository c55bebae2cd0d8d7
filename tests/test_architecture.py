"""The layering the design promises, checked on the source: data flows one way, learners and
users never see each other, nothing above world/ imports the simulator, no import cycles."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "activeintent"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, top_level_only: bool) -> set[str]:
    """activeintent modules imported by ``path`` (all imports, or only those run at import time)."""
    tree = ast.parse(path.read_text())
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    if top_level_only:  # imports under `if TYPE_CHECKING:` / try blocks at module level count too
        nodes = [n for stmt in tree.body for n in ast.walk(stmt)
                 if not isinstance(stmt, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)]
    out = set()
    for node in nodes:
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
])
def test_layering(package, forbidden):
    bad = [(name, imp) for name, path in MODULES.items() if name.startswith(package)
           for imp in imports(path, top_level_only=False) if imp.startswith(forbidden)]
    assert not bad, f"{package} must not import {forbidden}: {bad}"


def test_no_import_cycles():
    graph = {name: {m for m in imports(path, top_level_only=True) if m in MODULES and m != name}
             for name, path in MODULES.items()}
    # a package's __init__ importing its own submodules is not a cycle of meaning
    for name in graph:
        graph[name] = {m for m in graph[name] if not (MODULES[name].name == "__init__.py" and m.startswith(name + "."))}
    index, low, stack, on, cycles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
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
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles, f"import cycles: {cycles}"


def test_one_episode_loop_and_no_proxies():
    loops = [name for name, path in MODULES.items() if "def run_symbolic_episode" in path.read_text()]
    assert not loops
    web = [name for name, path in MODULES.items() if name.startswith("activeintent.web")
           and "def __getattr__" in path.read_text()]
    assert not web, f"web proxies the episode through __getattr__: {web}"
