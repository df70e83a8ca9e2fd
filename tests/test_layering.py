"""The package's layering: data flows one way (params -> model -> sim/servo -> studies/gap -> report -> cli).

Every import is read from the source (module level and inside functions), so an import hidden in a function
cannot make a cycle either.
"""

import ast
from pathlib import Path

import pytest

import drakecreep

PACKAGE = Path(drakecreep.__file__).parent

#: each room and the rooms it may import (besides itself); the base modules may be imported by every room
BASE = {"errors", "scenario", "params", "data", "files", "processes"}
ALLOWED = {
    "model": set(),
    "paper": {"model"},
    "multibody": {"model"},
    "sim": {"model", "paper", "multibody"},
    "servo": {"model", "paper", "sim", "multibody"},
    "studies": {"model", "paper", "sim", "servo", "multibody"},
    "gap": {"model", "paper", "sim", "servo", "multibody"},
    "report": {"model", "paper", "sim", "servo", "studies", "gap", "multibody"},
    "cli": {"model", "paper", "sim", "servo", "studies", "gap", "report", "multibody"},
}


def _module_name(path):
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path):
    """Every ``drakecreep`` module ``path`` imports, anywhere in the file."""
    tree = ast.parse(path.read_text())
    this = _module_name(path)
    package = this if path.name == "__init__.py" else this.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("drakecreep"))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                mod = f"{base}.{node.module}" if node.module else base
            else:
                mod = node.module or ""
            if mod.startswith("drakecreep"):
                out.add(mod)
                out.update(f"{mod}.{a.name}" for a in node.names)
    return {m for m in out if _exists(m)}


def _exists(name):
    rel = Path(*name.split(".")[1:]) if "." in name else Path()
    return (PACKAGE / rel).with_suffix(".py").is_file() or (PACKAGE / rel / "__init__.py").is_file()


def _graph():
    return {_module_name(p): _imports(p) for p in PACKAGE.rglob("*.py")}


def _room(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


@pytest.fixture(scope="module")
def graph():
    return _graph()


def test_every_import_goes_down_the_layers(graph):
    bad = []
    for mod, deps in graph.items():
        room = _room(mod)
        if room in ("", "__main__") or room in BASE:
            continue
        for dep in deps:
            target = _room(dep)
            if target in ("",) or target in BASE or target == room:
                continue
            if target not in ALLOWED.get(room, set()):
                bad.append(f"{mod} -> {dep}")
    assert not bad, "imports against the layering:\n" + "\n".join(sorted(bad))


def test_base_modules_import_only_base_modules(graph):
    for name in BASE:
        mod = f"drakecreep.{name}"
        for dep in graph.get(mod, ()):
            assert _room(dep) in BASE | {""}, f"{mod} -> {dep}"


def test_nothing_but_the_cli_imports_the_cli(graph):
    for mod, deps in graph.items():
        if _room(mod) in ("cli", "__main__"):
            continue
        assert not any(_room(d) == "cli" for d in deps), mod


def test_no_import_cycles(graph):
    # modules only (a package __init__ importing its own modules is not a cycle of logic)
    edges = {m: {d for d in deps if d != m and not (m.count(".") and d == m.rpartition(".")[0])}
             for m, deps in graph.items()}
    state, stack = {}, []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if nxt not in edges:
                continue
            if state.get(nxt) == 1 and not (nxt == "drakecreep" or node.startswith(nxt + ".") and
                                               nxt.count(".") < node.count(".")):
                cycle = stack[stack.index(nxt):] + [nxt]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            visit(node)


def test_library_modules_do_not_pick_a_matplotlib_backend():
    for path in PACKAGE.rglob("*.py"):
        if _room(_module_name(path)) == "cli":
            continue
        assert "matplotlib.use(" not in path.read_text(), path
