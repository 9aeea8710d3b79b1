"""The documented examples run: doctests of the public top-level names and README's Python blocks."""

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
