"""docs/architecture.md lists the source tree as it is: its file tables under
"### `fortran/src/`" and "### `python/ancfdrv/`" name exactly the .f90 and .py files of
those directories (reference: the file system), each with a line saying what it holds."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"


def listed(prefix: str) -> dict[str, str]:
    """The rows of the table under the heading ### `prefix`: {relative path: description}."""
    text = DOC.read_text()
    start = text.index(f"### `{prefix}`")
    end = text.find("\n### ", start + 1)
    block = text[start:end if end > 0 else len(text)]
    rows = re.findall(r"^\| `([^`]+)` \| (.*) \|$", block, flags=re.M)
    return dict(rows)


def tree(prefix: str, suffix: str) -> set[str]:
    base = ROOT / prefix
    return {p.relative_to(base).as_posix() for p in base.rglob(f"*{suffix}")}


def test_fortran_file_list_is_the_tree():
    rows = listed("fortran/src/")
    assert set(rows) == tree("fortran/src/", ".f90")
    assert all(len(line.strip()) > 10 for line in rows.values())


def test_python_file_list_is_the_tree():
    rows = listed("python/ancfdrv/")
    assert set(rows) == tree("python/ancfdrv/", ".py")
    assert all(len(line.strip()) > 5 for line in rows.values())
