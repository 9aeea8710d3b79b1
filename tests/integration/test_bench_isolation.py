"""The benchmark sits outside the library: ipmc_asym never imports ipmc_asym_bench, and
ipmc_asym_bench uses only the public face of ipmc_asym -- the names of ``ipmc_asym.__all__``; the
CLI's option helpers it needs are its own, so a change of the library's insides cannot break it
(:data:`PLUGIN_INTERFACE` is empty); AST of every module."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = "ipmc_asym_bench"

#: what the bench may import besides ``ipmc_asym.__all__``: nothing (a module -> names map, kept
#: as the place to widen it, with a reason, should a plugin ever need a CLI helper)
PLUGIN_INTERFACE: dict[str, set] = {}


def modules(top: str) -> list[Path]:
    return sorted((ROOT / top).rglob("*.py"))


def names_bench(text: str) -> bool:
    return text == BENCH or text.startswith(BENCH + ".") or text.startswith(BENCH + ":")


def bench_references(tree: ast.AST) -> list[str]:
    """Imports of ipmc_asym_bench, and string constants naming it as a module (importlib)."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names if names_bench(a.name)]
        elif isinstance(node, ast.ImportFrom) and node.module and names_bench(node.module):
            out.append(node.module)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and names_bench(node.value):
            out.append(repr(node.value))
    return out


def is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def private_uses(tree: ast.AST) -> list[str]:
    """``from ipmc_asym... import _name`` and ``x._name`` where ``x`` is bound to an ipmc_asym module."""
    out, library_names = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "ipmc_asym":
            for a in node.names:
                if is_private(a.name):
                    out.append(f"from {node.module} import {a.name}")
                library_names.add(a.asname or a.name)
            if any(is_private(p) for p in node.module.split(".")):
                out.append(f"from {node.module} import ...")
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "ipmc_asym":
                    library_names.add(a.asname or a.name.split(".")[0])
                    if any(is_private(p) for p in a.name.split(".")):
                        out.append(f"import {a.name}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and is_private(node.attr):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in library_names:
                out.append(f"{ast.unparse(node)}")
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "getattr":
            if len(node.args) >= 2 and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str) \
                    and is_private(node.args[1].value) and isinstance(node.args[0], ast.Name) \
                    and node.args[0].id in library_names:
                out.append(ast.unparse(node))
    return out


def face_violations(tree: ast.AST, public: set) -> list[str]:
    """Imports of ipmc_asym that are neither a name of ``public`` (``from ipmc_asym import X``,
    ``ia.X`` with ``import ipmc_asym as ia``) nor in :data:`PLUGIN_INTERFACE`."""
    out, aliases = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "ipmc_asym":
            allowed = public if node.module == "ipmc_asym" else PLUGIN_INTERFACE.get(node.module, set())
            out += [f"from {node.module} import {a.name}" for a in node.names if a.name not in allowed]
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name == "ipmc_asym":
                    aliases.add(a.asname or a.name)
                elif a.name.startswith("ipmc_asym."):
                    out.append(f"import {a.name}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases \
                and node.attr not in public:
            out.append(ast.unparse(node))
    return out


def test_the_bench_uses_only_the_public_face():
    import ipmc_asym

    public = set(ipmc_asym.__all__)
    bad = [f"{p.relative_to(ROOT)}: {u}" for p in modules(BENCH)
           for u in face_violations(ast.parse(p.read_text(encoding="utf-8")), public)]
    assert not bad, bad


@pytest.mark.parametrize("source, found", [
    ("from ipmc_asym.integral.api import moment\n", True),
    ("from ipmc_asym import moment_integral\n", False),
    ("from ipmc_asym import groups_arrays\n", True),
    ("import ipmc_asym as ia\nia.moment(1, 2)\n", False),
    ("import ipmc_asym as ia\nia.closed_model_id\n", True),
    ("import ipmc_asym.bvp.solver\n", True),
    ("from ipmc_asym.base.jsonio import dumps\n", True),
    ("from ipmc_asym.cli.common import add_size_option\n", True),
])
def test_the_face_check_can_fail(source, found):
    assert bool(face_violations(ast.parse(source), {"moment", "moment_integral"})) is found


def test_the_library_does_not_import_the_bench():
    bad = [f"{p.relative_to(ROOT)}: {r}" for p in modules("ipmc_asym")
           for r in bench_references(ast.parse(p.read_text(encoding="utf-8")))]
    assert not bad, bad


def test_the_bench_uses_only_public_names():
    files = modules(BENCH)
    assert files, "ipmc_asym_bench/ has no modules"
    bad = [f"{p.relative_to(ROOT)}: {u}" for p in files for u in private_uses(ast.parse(p.read_text(encoding="utf-8")))]
    assert not bad, bad


@pytest.mark.parametrize("source, found", [
    ("from ipmc_asym.integral.api import _sweep\n", True),
    ("import ipmc_asym.integral.api as api\napi._SCALAR_CACHE\n", True),
    ("from ipmc_asym.integral import api\nx = api._ORDER['leading']\n", True),
    ("import ipmc_asym\nipmc_asym.integral.api._sweep\n", True),
    ("from ipmc_asym.integral.api import moment\nimport numpy as np\nnp._NoValue\n", False),
    ("import ipmc_asym\nipmc_asym.__file__\n", False),
])
def test_the_private_name_check_can_fail(source, found):
    assert bool(private_uses(ast.parse(source))) is found


@pytest.mark.parametrize("source, found", [
    ("import ipmc_asym_bench.suite\n", True),
    ("from ipmc_asym_bench import suite\n", True),
    ("SECTIONS = {'x': 'ipmc_asym_bench.exact:section'}\n", True),
    ("from ipmc_asym.io.fileio import check_output_path\n", False),
])
def test_the_import_check_can_fail(source, found):
    assert bool(bench_references(ast.parse(source))) is found
