"""The on-disk cache of the hypothesis space is keyed by every source file its result depends on."""

from __future__ import annotations

import ast
import importlib.util
import os
import shutil
from pathlib import Path

from activeintent.learners.bayes import hypotheses as hyp


def _module_file(name: str) -> Path | None:
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return None
    return Path(spec.origin).resolve()


def _imported_files(path: Path) -> set[Path]:
    """Files of the activeintent modules that ``path`` imports (at any depth of its code)."""
    found: set[Path | None] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(_module_file(a.name) for a in node.names if a.name.startswith("activeintent."))
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("activeintent."):
            assert node.level == 0, f"{path}: relative imports are not followed"
            for alias in node.names:
                # "from pkg import mod" depends on pkg/mod.py; "from pkg import name" on pkg itself
                found.add(_module_file(f"{node.module}.{alias.name}") or _module_file(node.module))
    found.discard(None)
    return found  # type: ignore[return-value]


def _closure(start: Path) -> set[Path]:
    """``start`` and every activeintent source file it imports, directly or not (package
    __init__ files run only because of the import machinery are not followed)."""
    seen, todo = set(), [start.resolve()]
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        todo.extend(_imported_files(path) - seen)
    return seen


def _dependencies() -> set[Path]:
    """What the cached names are computed from: the grammar module, the goals modules its leaves
    come from, the goals package (it loads every node type), and all they import."""
    bayes = Path(hyp.__file__).resolve().parent
    goals = bayes.parents[1] / "goals"
    out: set[Path] = set()
    for path in (bayes / "hypotheses.py", goals / "__init__.py", goals / "language.py", goals / "recipes.py",
                 goals / "facts.py", goals / "planning.py"):
        out |= _closure(path)
    return out


def test_key_covers_every_module_the_grammar_imports():
    sources = {p.resolve() for p in hyp._cache_sources()}
    names = {f"{p.parent.name}/{p.name}" for p in sources}
    # the two inputs the old key left out
    assert {"world/state.py", "intentions/base.py"} <= names
    deps = _dependencies()
    # sanity of the import walk: it reaches the world model through the grammar
    assert {"world/state.py", "world/predict.py", "goals/facts.py", "goals/language.py", "goals/recipes.py",
            "goals/nodes.py", "goals/selectors.py", "goals/relations.py", "goals/structures.py", "goals/goal.py",
            "goals/requested.py"} <= {f"{p.parent.name}/{p.name}" for p in deps}
    missing = sorted(str(p) for p in deps - sources)
    assert not missing, f"the hypothesis cache key ignores {missing}"


def _copy_sources(dest: Path) -> list[Path]:
    copies = []
    for src in hyp._cache_sources():
        target = dest / src.parent.name / src.name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, target)
        copies.append(target)
    return copies


def test_changing_any_source_changes_the_key(tmp_path):
    copies = _copy_sources(tmp_path)
    base = hyp._cache_file(0, 6, copies)
    assert base == hyp._cache_file(0, 6)  # the key depends on contents, not on where they are
    unchanged = []
    for path in copies:
        original = path.read_bytes()
        path.write_bytes(original + b"\n# an edit\n")
        if hyp._cache_file(0, 6, copies) == base:
            unchanged.append(f"{path.parent.name}/{path.name}")
        path.write_bytes(original)
    assert not unchanged, f"editing these left the key unchanged: {unchanged}"
    assert hyp._cache_file(0, 6, copies) == base


def test_key_separates_settings_and_lives_in_the_cache_folder():
    assert len({hyp._cache_file(0, 6), hyp._cache_file(1, 6), hyp._cache_file(0, 5)}) == 3
    assert hyp._cache_file(0, 6).parent == Path(os.environ["ACTIVEINTENT_CACHE"])
