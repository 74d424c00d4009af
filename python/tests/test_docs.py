"""docs/python.md's ```python blocks run, in order, as one notebook from the repository's root,
on the installed package."""

import os
import re

from conftest import ROOT

PAGE = ROOT / "docs" / "python.md"


def python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)


def test_the_python_page_runs_as_a_notebook(capsys):
    blocks = python_blocks(PAGE.read_text())
    assert len(blocks) >= 5
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        scope: dict = {}
        for i, code in enumerate(blocks):
            exec(compile(code, f"{PAGE}:block{i + 1}", "exec"), scope)
    finally:
        os.chdir(cwd)
    printed = capsys.readouterr().out
    assert "refused: <study dict>" in printed
    assert "unknown field `latitude`" in printed
