"""The analysis scripts are run by users from the command line: each parses its arguments, so ``--help`` prints
its usage instead of starting the long job, and a wrong argument is refused with exit status 2."""

import ast
from pathlib import Path

import pytest

ANALYSIS = Path(__file__).resolve().parents[1] / "analysis"
SCRIPTS = sorted(p for p in ANALYSIS.glob("*.py") if '__name__ == "__main__"' in p.read_text())


def _parses_arguments(tree):
    """Whether the module imports argparse or the studies' shared command line (``study_cli``)."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name in ("argparse", "study_cli") for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module in ("argparse", "study_cli"):
            return True
    return False


def _indexes_argv(tree):
    """Whether the module reads ``sys.argv[...]`` itself (a missing argument is then an IndexError)."""
    return any(isinstance(node, ast.Subscript) and isinstance(node.value, ast.Attribute) and node.value.attr == "argv"
               for node in ast.walk(tree))


def test_there_are_scripts():
    assert len(SCRIPTS) > 30


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.name)
def test_each_script_parses_its_arguments(path):
    tree = ast.parse(path.read_text())
    assert _parses_arguments(tree), f"{path.name}: --help would run the job (no argparse)"
    assert not _indexes_argv(tree), f"{path.name}: reads sys.argv[...] itself"
