"""The documented examples run: doctests of the public top-level names, README's Python blocks and the
documentation pages' Python blocks."""

from __future__ import annotations

import doctest
import pathlib
import re

import pytest

import ipmc_asym

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _doctests():
    finder = doctest.DocTestFinder(recurse=False)
    seen, out = set(), []
    for name in ipmc_asym.__all__:
        obj = getattr(ipmc_asym, name)
        if not callable(obj) or id(obj) in seen:
            continue
        seen.add(id(obj))
        module = __import__(obj.__module__, fromlist=["_"])
        for t in finder.find(obj, name, module=module, globs=vars(module)):
            if t.examples:
                out.append(t)
    return out


DOCTESTS = _doctests()


def test_public_functions_have_doctests():
    names = {t.name for t in DOCTESTS}
    for name in ("fit", "read_fit_data", "uq", "profiles", "validate", "laws", "scene"):
        assert name in names or (name == "scene" and "run_scene" in names), name


@pytest.mark.parametrize("test", DOCTESTS, ids=[t.name for t in DOCTESTS])
def test_doctest(test):
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    res = runner.summarize(verbose=False)
    assert res.failed == 0, f"{test.name}: {res.failed} of {res.attempted} examples failed"


README_BLOCKS = re.findall(r"```python\n(.*?)```", (ROOT / "README.md").read_text(encoding="utf-8"), re.S)


def test_readme_has_python_blocks():
    assert README_BLOCKS


@pytest.mark.parametrize("code", README_BLOCKS, ids=[f"block{i}" for i in range(len(README_BLOCKS))])
def test_readme_block(code):
    exec(compile(code, "README.md", "exec"), {"__name__": "__readme__"})


def _docs_python_blocks(path: pathlib.Path) -> list[str]:
    """The ``.. code-block:: python`` blocks of an RST page (Markdown: the ```python blocks)."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".md":
        return re.findall(r"```python\n(.*?)```", text, re.S)
    blocks = []
    for m in re.finditer(r"^\.\. code-block:: python\n\n((?:(?:    .*)?\n)+)", text, re.M):
        blocks.append("\n".join(line[4:] for line in m.group(1).splitlines()))
    return blocks


DOC_PAGES = sorted(p for p in (ROOT / "docs").glob("*.*") if p.suffix in (".rst", ".md") and _docs_python_blocks(p))


def test_docs_have_python_blocks():
    assert any(p.name == "getting_started.rst" for p in DOC_PAGES)


@pytest.mark.parametrize("page", DOC_PAGES, ids=[p.name for p in DOC_PAGES])
def test_docs_page_blocks(page):
    """Every Python block of a page runs, in order, in one namespace (a page builds on its blocks)."""
    ns = {"__name__": "__docs__"}
    for i, code in enumerate(_docs_python_blocks(page)):
        exec(compile(code, f"{page.name}[block {i}]", "exec"), ns)


def test_no_untested_python_in_literal_blocks():
    """Python in a page is a ``code-block:: python`` (run above), never a bare ``::`` literal block."""
    for page in sorted((ROOT / "docs").glob("*.rst")):
        text = page.read_text(encoding="utf-8")
        for m in re.finditer(r"::\n\n((?:(?:    .*)?\n)+)", text):
            first = m.group(1).strip().splitlines()[0]
            assert not re.match(r"(import |from \S+ import |>>> )", first), f"{page.name}: {first!r}"
