"""The layer rule of docs/design.md, enforced on the imports of ipmc_asym/ and derivations/.

Every import (module level and inside functions) is read from the AST; an import that goes
up the written rule, a module without a layer, or an import cycle fails.
"""

from __future__ import annotations

import ast
import fnmatch
import functools
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@functools.lru_cache(maxsize=None)
def _parsed(text: str) -> ast.Module:
    # every test walks the same ~200 files: each text is parsed once per process (a changed file,
    # such as the checker's own upward-import fakes, is a new text and parsed anew)
    return ast.parse(text)


def parse(path: Path) -> ast.Module:
    return _parsed(path.read_text(encoding="utf-8"))


def read_layers(text: str) -> list[tuple[str, list[str]]]:
    block = re.search(r"```layers\n(.*?)```", text, re.S)
    assert block, "docs/design.md has no ```layers block"
    out = []
    for line in block.group(1).strip().splitlines():
        name, pats = line.split(":", 1)
        out.append((name.strip(), pats.split()))
    return out


def module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imports_of(path: Path, mod: str) -> set[str]:
    """Modules of the project imported by ``path`` (absolute names)."""
    return set(_imports(path.read_text(encoding="utf-8"), path.name, mod))


@functools.lru_cache(maxsize=None)
def _imports(text: str, filename: str, mod: str) -> frozenset:
    tree = _parsed(text)
    pkg = mod if filename == "__init__.py" else mod.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")
                base = base[: len(base) - (node.level - 1)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            # "from pkg import sub" may import a submodule: keep both candidates
            names = [prefix] + [f"{prefix}.{a.name}" for a in node.names]
        else:
            continue
        for n in names:
            # installed, derivations/ is the package ipmc_asym_derivations
            if n.split(".")[0] == "ipmc_asym_derivations":
                n = "derivations" + n[len("ipmc_asym_derivations"):]
            if n.split(".")[0] in ("ipmc_asym", "derivations"):
                found.add(n)
    return frozenset(found)


def project_modules() -> dict[str, Path]:
    mods = {}
    for top in ("ipmc_asym", "derivations"):
        for p in (ROOT / top).rglob("*.py"):
            mods[module_name(p)] = p
    return mods


def layer_of(mod: str, layers) -> int | None:
    for i, (_, pats) in enumerate(layers):
        if any(fnmatch.fnmatchcase(mod, p) for p in pats):
            return i
    return None


def graph(mods, layers):
    """module -> set of project modules it imports (resolved to existing modules)."""
    g = {}
    for m, p in mods.items():
        deps = set()
        for n in imports_of(p, m):
            while n and n not in mods:  # "from pkg import name": name is not a module
                n = n.rpartition(".")[0]
            if n and n != m:
                deps.add(n)
        g[m] = deps
    return g


def violations(mods, layers):
    g = graph(mods, layers)
    out = []
    for m, deps in g.items():
        lm = layer_of(m, layers)
        if lm is None:
            out.append(f"{m}: no layer in docs/design.md")
            continue
        for d in deps:
            ld = layer_of(d, layers)
            # a package's __init__ imported only as the parent of a submodule is fine
            if ld is not None and ld > lm and not (d in ("ipmc_asym",) and lm >= 0):
                out.append(f"{m} ({layers[lm][0]}) imports {d} ({layers[ld][0]}): upward")
    return out, g


def cycles(g) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in index:
                strong(w)
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
                out.append(sorted(comp))

    for v in list(g):
        if v not in index:
            strong(v)
    return out


LAYERS = read_layers((ROOT / "docs" / "design.md").read_text(encoding="utf-8"))


def read_studies_order(text: str) -> list[str]:
    block = re.search(r"```studies\n(.*?)```", text, re.S)
    assert block, "docs/design.md has no ```studies block"
    return [f"ipmc_asym.studies.{m}" for m in block.group(1).split()]


STUDIES = read_studies_order((ROOT / "docs" / "design.md").read_text(encoding="utf-8"))


def studies_violations(mods):
    """Imports inside ``studies/`` that go against its written order."""
    g = graph(mods, LAYERS)
    out = []
    for m in g:
        if not m.startswith("ipmc_asym.studies."):
            continue
        if m not in STUDIES:
            out.append(f"{m}: not in the studies order of docs/design.md")
            continue
        for d in g[m]:
            if d in STUDIES and STUDIES.index(d) > STUDIES.index(m):
                out.append(f"{m} imports {d}: later in the studies order")
    return out


def test_the_tree_is_the_layer_rule():
    """Every subpackage of ipmc_asym/ is a layer of the rule, and no module sits loose beside them."""
    pkg = ROOT / "ipmc_asym"
    loose = sorted(p.name for p in pkg.glob("*.py") if p.name not in ("__init__.py", "__main__.py"))
    assert not loose, f"modules outside a subpackage: {loose}"
    layer_names = [name for name, _ in LAYERS]
    folders = sorted(p.name for p in pkg.iterdir() if (p / "__init__.py").exists())
    missing = [f for f in folders if f not in layer_names]
    assert not missing, f"subpackages without a layer in docs/design.md: {missing}"


def test_studies_follow_their_order():
    bad = studies_violations(project_modules())
    assert not bad, "\n".join(bad)


def test_every_import_follows_the_layer_rule():
    bad, _ = violations(project_modules(), LAYERS)
    assert not bad, "\n".join(bad)


def test_no_import_cycle():
    _, g = violations(project_modules(), LAYERS)
    # the package itself only re-exports lazily; drop it so that "ipmc_asym.x imports ipmc_asym"
    # (for __version__) is not read as a cycle through every submodule
    g = {m: {d for d in deps if d != "ipmc_asym"} for m, deps in g.items()}
    assert not cycles(g), cycles(g)


def test_nothing_outside_the_cli_imports_it():
    g = graph(project_modules(), LAYERS)
    bad = [m for m, deps in g.items() if not m.startswith("ipmc_asym.cli") and m != "ipmc_asym.__main__"
           and any(d.startswith("ipmc_asym.cli") for d in deps)]
    assert not bad, bad


#: the generic figure of every result type (``.plot()``): in ``base/`` so that the results of the
#: low layers (bvp, integral, forward, dynamics) can draw themselves without importing plotting/
RESULT_FIGURES = "ipmc_asym.base.results"


def test_only_plotting_imports_matplotlib():
    bad = []
    for m, p in project_modules().items():
        if m.startswith("ipmc_asym.plotting") or m == RESULT_FIGURES:
            continue
        tree = parse(p)
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n.split(".")[0] == "matplotlib" for n in names):
                bad.append(m)
    assert not bad, bad


@pytest.mark.parametrize("upward", [
    ("ipmc_asym/model/params.py", "from ipmc_asym.integral.api import moment\n"),
    ("ipmc_asym/studies/sweeps.py", "from ipmc_asym.cli.common import UsageError\n"),
    ("ipmc_asym/beam/statics.py", "from ipmc_asym.plotting import pyplot\n"),
    ("ipmc_asym/studies/fits.py", "from ipmc_asym.studies.uq import run_uq\n"),
])
def test_the_rule_fails_on_an_upward_import(upward, tmp_path, monkeypatch):
    """The checker itself: an added upward import is reported (the test can fail)."""
    rel, line = upward
    mods = project_modules()
    target = ROOT / rel
    fake = tmp_path / rel
    fake.parent.mkdir(parents=True, exist_ok=True)
    fake.write_text(target.read_text(encoding="utf-8") + "\n" + line, encoding="utf-8")
    name = module_name(target)
    monkeypatch.setitem(mods, name, fake)
    real_module_name = module_name

    def shim(path):
        return name if path == fake else real_module_name(path)

    monkeypatch.setattr(sys.modules[__name__], "module_name", shim)
    bad, _ = violations(mods, LAYERS)
    bad += studies_violations(mods)
    assert any(b.startswith(name) for b in bad), bad


def test_a_cycle_is_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def local_imports(path: Path) -> list[tuple[int, str]]:
    """Function-level imports of ``path`` without a ``deferred:`` reason on their line(s)."""
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    out = []
    for node in ast.walk(_parsed(text)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for sub in ast.walk(node):
            if isinstance(sub, (ast.Import, ast.ImportFrom)):
                span = lines[sub.lineno - 1: sub.end_lineno]
                if not any("deferred:" in ln for ln in span):
                    out.append((sub.lineno, lines[sub.lineno - 1].strip()))
    return out


def test_function_level_imports_are_declared():
    """Imports sit at module level; one inside a function is there for a reason written on its
    line (``# deferred: heavy module, start-up`` or ``# deferred: optional extra``)."""
    bad = [f"{m}:{n}: {line}" for m, p in sorted(project_modules().items()) for n, line in local_imports(p)]
    assert not bad, f"{len(bad)} undeclared function-level imports:\n" + "\n".join(bad)
