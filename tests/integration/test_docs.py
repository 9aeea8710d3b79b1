"""The documented examples run: doctests of the public top-level names, README's Python blocks and the
documentation pages' Python blocks."""

from __future__ import annotations

import doctest
import pathlib
import re

import pytest

import ipmc_asym

ROOT = pathlib.Path(__file__).resolve().parents[2]


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


#: doctests that draw every figure of the paper (~10 s): run in CI; the dev loop draws them in
#: tests/plotting/test_figures.py
_SLOW_DOCTESTS = ("figures",)


@pytest.mark.parametrize("test", [pytest.param(t, marks=pytest.mark.slow) if t.name in _SLOW_DOCTESTS else t
                                  for t in DOCTESTS], ids=[t.name for t in DOCTESTS])
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


# --- the landing page and the site ---------------------------------------------------------------
README_TEXT = (ROOT / "README.md").read_text(encoding="utf-8")
INSTALL_MAIN = "python3 -m venv .venv && . .venv/bin/activate && pip install . && ipmc-asym estimate"
INSTALL_TESTS = ('python3 -m venv .venv && . .venv/bin/activate && pip install -e ".[test]" && '
                 "python -m pytest -q -n auto --durations=10")


def test_readme_is_a_landing_page():
    """At most 150 lines, the two commands as .ci/run runs them, links to pages that exist."""
    assert len(README_TEXT.splitlines()) <= 150
    assert INSTALL_MAIN in README_TEXT and INSTALL_TESTS in README_TEXT
    for target in re.findall(r"\]\(((?:docs/)?[\w./-]+\.(?:md|rst|cff))\)", README_TEXT):
        assert (ROOT / target).is_file(), target


def _api_names(text):
    """Names documented on api.rst: autosummary entries and ``py:data`` directives."""
    names = set(re.findall(r"^\.\. py:data:: (\w+)", text, re.M))
    for block in re.findall(r"^\.\. autosummary::\n(?:   :.*\n)*\n((?:   \S.*\n)+)", text, re.M):
        names |= {line.strip() for line in block.splitlines()}
    return names


def test_api_page_lists_every_public_name():
    names = _api_names((ROOT / "docs" / "api.rst").read_text(encoding="utf-8"))
    assert set(ipmc_asym.__all__) <= names, sorted(set(ipmc_asym.__all__) - names)


def test_api_names_parser_sees_a_missing_name():
    text = ".. autosummary::\n   :toctree: generated\n\n   fit\n   uq\n\n.. py:data:: MODELS\n"
    assert _api_names(text) == {"fit", "uq", "MODELS"}


def _check_site():
    import importlib.util

    spec = importlib.util.spec_from_file_location("check_site", ROOT / "docs" / "check_site.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("tag, remote", [
    ('<script src="https://cdn.example.org/mathjax/tex-chtml.js"></script>', True),
    ("<script src='//cdn.example.org/x.js'></script>", True),
    ('<link rel="stylesheet" href="https://fonts.example.org/a.css">', True),
    ('<script src="_static/mathjax/tex-chtml.js"></script>', False),
    ('<a href="https://doi.org/10.1021/jp011316u">Goswami 2001</a>', False),
    ('<link rel="canonical" href="https://example.org/">', False),
])
def test_site_check_finds_remote_loads(tmp_path, tag, remote):
    """The check .ci/run applies to the built site: it fails on a fetched remote resource only."""
    site = _check_site()
    (tmp_path / "page.html").write_text(f"<html><head>{tag}</head></html>", encoding="utf-8")
    assert bool(site.remote_loads(tmp_path)) is remote
    (tmp_path / "api.html").write_text('<dt id="ipmc_asym.fit">', encoding="utf-8")
    assert site.missing_api_names(tmp_path, ["fit", "uq"]) == ["uq"]


def test_docs_extra_builds_offline_and_runs_the_gallery():
    """The docs extra holds what the build needs: the offline MathJax, the theme, dask for the
    cluster example of the gallery."""
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    docs = re.search(r"^docs = \[(.*?)\]", text, re.M | re.S).group(1)
    for pkg in ("sphinx", "sphinx-gallery", "numpydoc", "myst-parser", "furo", "sphinx-mathjax-offline",
                "distributed"):
        assert pkg in docs, pkg
    conf = (ROOT / "docs" / "conf.py").read_text(encoding="utf-8")
    assert '"sphinx-mathjax-offline"' in conf and "autodoc_preserve_defaults = True" in conf
