"""The Python blocks of the user docs run as written (in order, one namespace per page)."""

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = ["tutorial.md"]


def _blocks(page):
    return re.findall(r"^```python\n(.*?)^```", (DOCS / page).read_text(), flags=re.S | re.M)


@pytest.mark.parametrize("page", PAGES)
def test_python_blocks_run(page, tmp_path, monkeypatch, capsys):
    blocks = _blocks(page)
    assert blocks, f"{page} has no python block"
    monkeypatch.chdir(tmp_path)  # files the page writes land here
    namespace = {"__name__": f"docs.{page}"}
    for i, code in enumerate(blocks):
        exec(compile(code, f"{page}[block {i}]", "exec"), namespace)
